pub fn run(_a: &crate::cli::ExperimentArgs, _s: &std::sync::atomic::AtomicBool) -> anyhow::Result<std::process::ExitCode> { todo!() }
