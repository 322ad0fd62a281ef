//! [`Trims`]: each joint's amplifier as it is, not as it should be. An amplifier's
//! current is zero not at zero duty but at an *offset*, and no current flows until the
//! duty is a *dead band* past it; the device file gives both per joint (`duty_offset`,
//! `dead_band`, fractions of full duty, measured by the locked-rotor sweep of
//! docs/arm.md). [`Trims::apply`] turns the duty the current needs into the duty to
//! write: `offset + d + sign(d) · band` for `|d| ≥ band`, and `offset + 2d` inside it,
//! so that the map is continuous and monotonic (no jump through zero force for noise to
//! chatter on), held to ±100 %.
//!
//! Q16 throughout (±65,536 = ±100 %); no division, no panic path: `apply` is
//! branch-light integer arithmetic on `i32`s bounded by construction (`|offset|`,
//! `band` ≤ 13,108 by [`mccs::ArmSpec::validate`]'s ±0.2, and the result clamped to
//! constant bounds).

/// Each joint's trims, Q16.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Trims {
    /// The duty at zero current, Q16 (−13,107 … 13,107).
    pub offset_q16: [i32; 3],
    /// The dead band past the offset, Q16 (0 … 13,107).
    pub band_q16: [i32; 3],
}

/// 100 % duty, Q16.
const FULL_DUTY_Q16: i32 = 1 << 16;
/// The trims' bound, Q16: 0.2 of full duty (what `validate` admits), held here too.
const TRIM_MAX: i32 = 13_108;

impl Trims {
    /// The trims of `spec`'s joints (start-up: floating point; each held to ±0.2).
    pub fn of(spec: &mccs::ArmSpec) -> Self {
        let q16 = |x: f64| (libm::round(x * 65_536.0) as i32).clamp(-TRIM_MAX, TRIM_MAX);
        let j = &spec.joints;
        Trims {
            offset_q16: [0, 1, 2].map(|k| q16(j[k].duty_offset)),
            band_q16: [0, 1, 2].map(|k| q16(j[k].dead_band).max(0)),
        }
    }

    /// The duties to write for the duties the currents need (Q16, ±65,536).
    #[inline(always)]
    pub fn apply(&self, duty: [i32; 3]) -> [i32; 3] {
        let mut out = [0; 3];
        for k in 0..3 {
            out[k] = trim(duty[k], self.offset_q16[k], self.band_q16[k]);
        }
        out
    }
}

/// One joint's duty through its trims.
#[inline(always)]
fn trim(duty: i32, offset: i32, band: i32) -> i32 {
    let d = duty.clamp(-FULL_DUTY_Q16, FULL_DUTY_Q16);
    // (Saturating: the fields are public, whatever `of` holds them to.)
    let past = if d >= band {
        d.saturating_add(band)
    } else if d <= band.saturating_neg() {
        d.saturating_sub(band)
    } else {
        2 * d
    };
    past.saturating_add(offset)
        .clamp(-FULL_DUTY_Q16, FULL_DUTY_Q16)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_trims_change_nothing() {
        let t = Trims::default();
        for d in [-FULL_DUTY_Q16, -1, 0, 1, 12_345, FULL_DUTY_Q16] {
            assert_eq!(t.apply([d, d, d]), [d, d, d]);
        }
    }

    #[test]
    fn zero_current_is_the_offset_and_past_the_band_the_duty_is_shifted_by_it() {
        let (offset, band) = (1_000, 3_000);
        assert_eq!(trim(0, offset, band), offset);
        assert_eq!(trim(10_000, offset, band), 10_000 + band + offset);
        assert_eq!(trim(-10_000, offset, band), -10_000 - band + offset);
        assert_eq!(
            trim(FULL_DUTY_Q16, offset, band),
            FULL_DUTY_Q16,
            "held to 100 %"
        );
        assert_eq!(trim(-FULL_DUTY_Q16, -offset, band), -FULL_DUTY_Q16);
    }

    #[test]
    fn the_map_is_continuous_and_monotonic_over_the_whole_domain() {
        for (offset, band) in [(0, 0), (1_311, 655), (-TRIM_MAX, TRIM_MAX), (TRIM_MAX, 1)] {
            let mut last = trim(-FULL_DUTY_Q16 - 5, offset, band);
            for d in -FULL_DUTY_Q16 - 4..=FULL_DUTY_Q16 + 4 {
                let y = trim(d, offset, band);
                assert!(
                    y >= last && y - last <= 2,
                    "d={d} {last}→{y} ({offset}, {band})"
                );
                assert!((-FULL_DUTY_Q16..=FULL_DUTY_Q16).contains(&y));
                last = y;
            }
        }
    }

    #[test]
    fn trims_beyond_their_bound_saturate_and_never_overflow() {
        for (offset, band) in [
            (i32::MAX, i32::MAX),
            (i32::MIN, 0),
            (0, i32::MIN),
            (i32::MIN, i32::MAX),
        ] {
            for d in [i32::MIN, -FULL_DUTY_Q16, -1, 0, 1, FULL_DUTY_Q16, i32::MAX] {
                assert!((-FULL_DUTY_Q16..=FULL_DUTY_Q16).contains(&trim(d, offset, band)));
            }
        }
    }

    #[test]
    fn a_spec_s_trims_are_its_fractions_in_q16_held_to_the_bound() {
        let mut spec = crate::arm::device::WOODENHAPTICS;
        spec.joints[0].duty_offset = 0.015;
        spec.joints[1].dead_band = 0.02;
        spec.joints[2].duty_offset = -0.9; // (validate refuses it; held here anyway)
        let t = Trims::of(&spec);
        assert_eq!(t.offset_q16, [983, 0, -TRIM_MAX]);
        assert_eq!(t.band_q16, [0, 1_311, 0]);
    }
}
