//! What a host says about a tissue: where it lies ([`Pose`]), its friction
//! ([`Friction`]) and its load's announcement ([`TissueBegin`]).

use postcard_schema::Schema;
use serde::{Deserialize, Serialize};

/// The most table bytes one [`ToDevice::TissueChunk`](crate::ToDevice::TissueChunk) carries (its frame stays within
/// [`crate::MAX_FRAME`]).
pub const TISSUE_CHUNK: usize = 200;

/// A pose of the tissue in the device's frame: a point `p` of the tissue's frame is at
/// `origin + R p`, `R` the rotation of the unit quaternion `rotation`.
#[derive(Serialize, Deserialize, Schema, Clone, Copy, Debug, PartialEq, Eq)]
pub struct Pose {
    /// The tissue frame's origin, Q24 mm.
    pub origin: [i32; 3],
    /// The rotation, a unit quaternion `w, x, y, z`, Q30.
    pub rotation: [i32; 4],
}

impl Default for Pose {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Pose {
    /// At the device's origin, unrotated.
    pub const IDENTITY: Pose = Pose {
        origin: [0; 3],
        rotation: [1 << 30, 0, 0, 0],
    };

    /// From mm and three angles in degrees: the rotation `Rz(rz) Ry(ry) Rx(rx)` (about
    /// the device's `x`, then `y`, then `z`).
    pub fn from_mm_deg(origin: [f64; 3], angles_deg: [f64; 3]) -> Pose {
        let half = angles_deg.map(|a| a.to_radians() / 2.0);
        let (s, c) = (half.map(libm::sin), half.map(libm::cos));
        // q = qz ⊗ qy ⊗ qx.
        let w = c[2] * c[1] * c[0] + s[2] * s[1] * s[0];
        let x = c[2] * c[1] * s[0] - s[2] * s[1] * c[0];
        let y = c[2] * s[1] * c[0] + s[2] * c[1] * s[0];
        let z = s[2] * c[1] * c[0] - c[2] * s[1] * s[0];
        Pose {
            origin: origin.map(crate::scale::mm_bits),
            rotation: [w, x, y, z].map(|q| crate::scale::from_f64(q, crate::scale::QUAT_FRAC)),
        }
    }

    /// The origin, mm.
    pub fn origin_mm(&self) -> [f64; 3] {
        self.origin.map(crate::scale::mm)
    }

    /// The rotation as angles `rx, ry, rz` in degrees (`R = Rz Ry Rx`; `ry` within ±90°).
    pub fn angles_deg(&self) -> [f64; 3] {
        let [w, x, y, z] = self
            .rotation
            .map(|q| crate::scale::to_f64(q, crate::scale::QUAT_FRAC));
        let rx = libm::atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y));
        let sy = (2.0 * (w * y - z * x)).clamp(-1.0, 1.0);
        let ry = libm::asin(sy);
        let rz = libm::atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z));
        [rx, ry, rz].map(f64::to_degrees)
    }
}

/// Friction coefficients, Q16: static `mu_s` ≥ kinetic `mu_k`, each 0 … 2.
#[derive(Serialize, Deserialize, Schema, Clone, Copy, Debug, PartialEq, Eq)]
pub struct Friction {
    /// Static, Q16.
    pub mu_s: u32,
    /// Kinetic, Q16.
    pub mu_k: u32,
}

impl Friction {
    /// The largest coefficient, Q16 (2).
    pub const MAX: u32 = 2 << crate::scale::FRICTION_FRAC;

    /// From two numbers (rounded to Q16; the device checks them).
    pub fn new(mu_s: f64, mu_k: f64) -> Friction {
        let q = |x: f64| crate::scale::from_f64(x, crate::scale::FRICTION_FRAC).max(0) as u32;
        Friction {
            mu_s: q(mu_s),
            mu_k: q(mu_k),
        }
    }

    /// `(mu_s, mu_k)` as numbers.
    pub fn values(&self) -> (f64, f64) {
        let f = |q: u32| q as f64 / (1u32 << crate::scale::FRICTION_FRAC) as f64;
        (f(self.mu_s), f(self.mu_k))
    }

    /// Whether a device takes it: each at most 2, `mu_k ≤ mu_s`.
    pub fn valid(&self) -> bool {
        self.mu_s <= Self::MAX && self.mu_k <= self.mu_s
    }
}

/// What a tissue load announces: the force table's `segments` (knots − 1), its length
/// in bytes and its hash ([`crate::table_bytes`]), the tissue's friction (none: keep the
/// live one's), and the substeps the host computed for the device's patch (0: the device
/// searches for them, which takes seconds on a small core; it checks a host's number
/// either way).
#[derive(Serialize, Deserialize, Schema, Clone, Copy, Debug, PartialEq, Eq)]
pub struct TissueBegin {
    /// Segments.
    pub segments: u16,
    /// Bytes to come.
    pub len: u32,
    /// FNV-1a of the bytes.
    pub hash: u32,
    /// The tissue's friction, or the live one's.
    pub friction: Option<Friction>,
    /// Substeps per tick the host proposes (0: none).
    pub substeps: u16,
}
