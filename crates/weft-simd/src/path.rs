//! Which instruction set the constraint kernel runs on: picked from the CPU, or forced by
//! the solver's `Settings::simd` or the `WEFT_SIMD` environment variable (read once).
//!
//! Every path runs the same IEEE operations in the same order on the same lanes, so the path
//! changes the speed, never the result (`tests/integration/determinism.rs` checks each path this CPU has).

use std::fmt;
use std::str::FromStr;
use std::sync::OnceLock;

use thiserror::Error;

/// The environment variable that forces a kernel path when the solver's `Settings::simd` is `None`.
pub const SIMD_ENV: &str = "WEFT_SIMD";

/// A kernel path: the instruction set the domain sweep and integration are compiled for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum SimdPath {
    /// x86-64 with AVX-512 (F, VL, DQ), AVX2 and FMA: 512-bit vectors.
    Avx512,
    /// x86-64 with AVX2 and FMA: 256-bit vectors.
    Avx2,
    /// AArch64 with NEON: 128-bit vectors.
    Neon,
    /// The baseline target with no extension (SSE2 on x86-64).
    #[default]
    Scalar,
}

/// A `WEFT_SIMD` value or path name that names no kernel path.
#[derive(Clone, Debug, Error, PartialEq, Eq)]
#[error("unknown SIMD path `{0}`: expected avx512, avx2, neon or scalar")]
pub struct UnknownSimdPath(pub String);

impl SimdPath {
    /// Every path, widest first.
    pub const ALL: [SimdPath; 4] = [Self::Avx512, Self::Avx2, Self::Neon, Self::Scalar];

    /// The path's name, as `WEFT_SIMD` takes it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Avx512 => "avx512",
            Self::Avx2 => "avx2",
            Self::Neon => "neon",
            Self::Scalar => "scalar",
        }
    }

    /// Whether this CPU can run the path.
    pub fn supported(self) -> bool {
        match self {
            #[cfg(target_arch = "x86_64")]
            Self::Avx512 => {
                std::is_x86_feature_detected!("avx512f")
                    && std::is_x86_feature_detected!("avx512vl")
                    && std::is_x86_feature_detected!("avx512dq")
                    && Self::Avx2.supported()
            }
            #[cfg(target_arch = "x86_64")]
            Self::Avx2 => {
                std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma")
            }
            #[cfg(target_arch = "aarch64")]
            Self::Neon => std::arch::is_aarch64_feature_detected!("neon"),
            Self::Scalar => true,
            #[allow(unreachable_patterns)]
            _ => false,
        }
    }

    /// The widest path this CPU can run.
    pub fn widest() -> Self {
        Self::ALL
            .into_iter()
            .find(|p| p.supported())
            .unwrap_or(Self::Scalar)
    }

    /// The path `WEFT_SIMD` asks for, read once per process: `Ok(None)` when it is unset or
    /// empty (or `auto`), an error when it names no path.
    pub fn from_env() -> Result<Option<Self>, UnknownSimdPath> {
        static VALUE: OnceLock<Option<String>> = OnceLock::new();
        let value = VALUE.get_or_init(|| std::env::var(SIMD_ENV).ok());
        match value.as_deref().map(str::trim) {
            None | Some("" | "auto") => Ok(None),
            Some(v) => v.parse().map(Some),
        }
    }

    /// The path a solver runs: `request` (or else `WEFT_SIMD`, or else the widest), lowered to
    /// the widest path this CPU can run when it cannot run the one asked for. A `WEFT_SIMD`
    /// that names no path counts as unset here; [`Self::from_env`] reports it.
    pub fn resolve(request: Option<Self>) -> Self {
        let asked = request.or_else(|| Self::from_env().ok().flatten());
        match asked {
            Some(p) if p.supported() => p,
            Some(p) => Self::ALL
                .into_iter()
                .skip_while(|&q| q != p)
                .find(|q| q.supported())
                .unwrap_or(Self::Scalar),
            None => Self::widest(),
        }
    }
}

impl fmt::Display for SimdPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for SimdPath {
    type Err = UnknownSimdPath;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|p| p.name().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| UnknownSimdPath(s.to_owned()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_unknown_names_are_errors() {
        for p in SimdPath::ALL {
            assert_eq!(p.name().parse::<SimdPath>(), Ok(p));
        }
        assert_eq!("AVX2".parse::<SimdPath>(), Ok(SimdPath::Avx2));
        let e = "sse9".parse::<SimdPath>().expect_err("no such path");
        assert!(e.to_string().contains("`sse9`"), "{e}");
    }

    #[test]
    fn a_forced_path_runs_when_supported_and_is_lowered_otherwise() {
        assert!(SimdPath::Scalar.supported());
        for p in SimdPath::ALL {
            let got = SimdPath::resolve(Some(p));
            assert!(got.supported(), "{p} -> {got}");
            if p.supported() {
                assert_eq!(got, p);
            }
        }
        assert!(SimdPath::widest().supported());
    }
}
