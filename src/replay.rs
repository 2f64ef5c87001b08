pub fn replay(_a: &crate::cli::ReplayArgs, _s: &std::sync::atomic::AtomicBool) -> anyhow::Result<std::process::ExitCode> { todo!() }
