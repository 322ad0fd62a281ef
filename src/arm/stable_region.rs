//! The arm's stable region (start-up and host only): the largest coupling stiffness a
//! held press stays stable with, at each coupling damping, as `mccs arm stability`
//! measures it on the simulated arm and writes it into the device file's `[stability]`
//! (docs/safety.md). One rule for every reader: `mccs check --device arm` and the board
//! at start-up allow half of it.

/// The region's stiffness (N/mm) at `damping` (N·s/m), of `points` (`(damping,
/// stiffness)`, the dampings rising): a measured point's, or between two the lower of
/// theirs (nothing is known between them); `None` outside them, or for a damping that
/// is not a number.
pub fn stable_coupling(points: &[(f64, f64)], damping: f64) -> Option<f64> {
    if let Some(&(_, k)) = points.iter().find(|(b, _)| *b == damping) {
        return Some(k);
    }
    points.windows(2).find_map(|w| {
        let ((b0, k0), (b1, k1)) = (w[0], w[1]);
        (b0 < damping && damping < b1).then_some(k0.min(k1))
    })
}

#[cfg(test)]
mod tests {
    use super::stable_coupling;

    #[test]
    fn a_measured_point_between_points_and_outside() {
        let r = [(0.0, 16.0), (0.5, 64.0), (5.0, 32.0)];
        assert_eq!(stable_coupling(&r, 0.0), Some(16.0));
        assert_eq!(stable_coupling(&r, 0.5), Some(64.0));
        assert_eq!(stable_coupling(&r, 0.25), Some(16.0));
        assert_eq!(stable_coupling(&r, 1.0), Some(32.0));
        assert_eq!(stable_coupling(&r, 5.0), Some(32.0));
        for outside in [-0.1, 5.1, f64::NAN, f64::INFINITY] {
            assert_eq!(stable_coupling(&r, outside), None, "{outside}");
        }
        assert_eq!(stable_coupling(&[], 0.5), None);
    }
}
