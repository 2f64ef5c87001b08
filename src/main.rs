//! The `weft` binary.
fn main() -> anyhow::Result<()> {
    Ok(())
}
