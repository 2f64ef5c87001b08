//! Which logged frames an export writes: `--frames A..B` and `--every N`.

use crate::cli::FrameRange;

/// The frames of `logged` (in order) that lie in `range`, then every `every`-th of them,
/// starting with the first.
pub fn select(logged: &[u64], range: Option<FrameRange>, every: u64) -> Vec<u64> {
    let every = usize::try_from(every.max(1)).unwrap_or(usize::MAX);
    logged
        .iter()
        .copied()
        .filter(|&f| range.is_none_or(|r| r.contains(f)))
        .step_by(every)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_parse_as_rust_writes_them() {
        let r = |s| FrameRange::parse(s).expect(s);
        assert_eq!(
            r("2..5"),
            FrameRange {
                start: 2,
                end: Some(5)
            }
        );
        assert_eq!(
            r("2..=5"),
            FrameRange {
                start: 2,
                end: Some(6)
            }
        );
        assert_eq!(
            r("7.."),
            FrameRange {
                start: 7,
                end: None
            }
        );
        assert_eq!(
            r("..3"),
            FrameRange {
                start: 0,
                end: Some(3)
            }
        );
        assert_eq!(
            r(".."),
            FrameRange {
                start: 0,
                end: None
            }
        );
        for bad in ["", "5", "a..b", "5..5", "6..2", "-1..4", "1..=x"] {
            assert!(FrameRange::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn every_nth_frame_of_the_range_is_kept() {
        let logged: Vec<u64> = (0..=10).collect();
        let range = FrameRange::parse("2..9").ok();
        assert_eq!(select(&logged, range, 3), vec![2, 5, 8]);
        assert_eq!(select(&logged, None, 4), vec![0, 4, 8]);
        assert_eq!(
            select(&logged, FrameRange::parse("20..").ok(), 1),
            Vec::<u64>::new()
        );
    }
}
