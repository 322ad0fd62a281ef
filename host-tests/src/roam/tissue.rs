//! The tissue: a surface grid of `W × H` nodes at spacing `s` (mm), flat or shaped by a
//! spherical cap, larger than the patch that simulates a window of it. Only rest
//! positions are computed here, from the grid coordinates; nothing is stored per node.

use super::RoamError;
use crate::patch::{Mesh, V};

/// Largest tissue side, nodes (the 64 × 64).
pub const MAX_SIDE: usize = 64;
/// Largest distance of a tissue node from the tissue's centre, mm, per axis: the core's
/// length format holds ±128 mm, and its topology takes nodes within ±100 mm.
pub const MAX_EXTENT_MM: f64 = 100.0;
/// Largest cap radius, mm (the core's `R` in Q20).
pub const MAX_CAP_RADIUS_MM: f64 = 2000.0;

/// The rest surface's shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// `z = 0`.
    Flat,
    /// A spherical cap of radius `R` mm whose top is at the tissue's centre at `z = 0`:
    /// `z = √(R² − x² − y²) − R`. `R` must exceed the tissue's half-diagonal by a third,
    /// so that the slope stays below about 1.2 everywhere, and be at most 2000 mm.
    Cap {
        /// Radius, mm.
        radius: f64,
    },
}

/// A tissue grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tissue {
    /// Nodes along `x`.
    pub w: usize,
    /// Nodes along `y`.
    pub h: usize,
    /// Spacing, mm.
    pub spacing: f64,
    /// Rest surface.
    pub shape: Shape,
}

impl Tissue {
    /// A tissue of `w × h` nodes (3 … 64 each) at `spacing` mm, centred on the origin.
    pub fn new(w: usize, h: usize, spacing: f64, shape: Shape) -> Result<Tissue, RoamError> {
        if !(3..=MAX_SIDE).contains(&w) || !(3..=MAX_SIDE).contains(&h) {
            return Err(RoamError::TissueSize);
        }
        if !spacing.is_finite() || spacing < 1.0 {
            return Err(RoamError::Spacing);
        }
        let t = Tissue {
            w,
            h,
            spacing,
            shape,
        };
        let (hx, hy) = t.half_extent();
        if hx.max(hy) > MAX_EXTENT_MM {
            return Err(RoamError::TissueExtent);
        }
        if let Shape::Cap { radius } = shape {
            let half_diagonal = (hx * hx + hy * hy).sqrt();
            if !radius.is_finite()
                || radius < 4.0 / 3.0 * half_diagonal
                || radius > MAX_CAP_RADIUS_MM
            {
                return Err(RoamError::CapRadius);
            }
        }
        Ok(t)
    }

    /// Half the tissue's size along `x` and `y`, mm.
    pub fn half_extent(&self) -> (f64, f64) {
        (
            (self.w - 1) as f64 * self.spacing / 2.0,
            (self.h - 1) as f64 * self.spacing / 2.0,
        )
    }

    /// Rest height of the surface above `(x, y)`, mm.
    pub fn height(&self, x: f64, y: f64) -> f64 {
        match self.shape {
            Shape::Flat => 0.0,
            Shape::Cap { radius } => (radius * radius - x * x - y * y).max(0.0).sqrt() - radius,
        }
    }

    /// The rest surface's upward unit normal above `(x, y)`.
    pub fn normal(&self, x: f64, y: f64) -> V {
        match self.shape {
            Shape::Flat => [0.0, 0.0, 1.0],
            Shape::Cap { radius } => {
                let z = self.height(x, y) + radius;
                let l = (x * x + y * y + z * z).sqrt();
                [x / l, y / l, z / l]
            }
        }
    }

    /// Where the rest surface's normal through `p` (mm) meets it, as `(x, y)`: the
    /// direction along which the probe's depth is measured.
    pub fn project(&self, p: V) -> (f64, f64) {
        match self.shape {
            Shape::Flat => (p[0], p[1]),
            Shape::Cap { radius } => {
                // Along the ray from the sphere's centre (0, 0, −R) through p.
                let d = [p[0], p[1], p[2] + radius];
                let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                if l > 0.0 {
                    (d[0] * radius / l, d[1] * radius / l)
                } else {
                    (0.0, 0.0)
                }
            }
        }
    }

    /// Rest position of tissue node `(i, j)`, mm.
    pub fn rest(&self, i: usize, j: usize) -> V {
        let (x, y) = self.xy(i as f64, j as f64);
        [x, y, self.height(x, y)]
    }

    /// The point `(x, y)` (mm) at continuous grid coordinates `(u, v)`.
    pub fn xy(&self, u: f64, v: f64) -> (f64, f64) {
        let (hx, hy) = self.half_extent();
        (u * self.spacing - hx, v * self.spacing - hy)
    }

    /// Continuous grid coordinates `(u, v)` of the point `(x, y)` (mm).
    pub fn grid(&self, x: f64, y: f64) -> (f64, f64) {
        let (hx, hy) = self.half_extent();
        ((x + hx) / self.spacing, (y + hy) / self.spacing)
    }

    /// The patch mesh of an `n × n` window whose corner is tissue node `(i0, j0)`: the
    /// standard patch's springs over the tissue's rest surface, each base node `spacing`
    /// below its surface node, the outer ring fixed.
    pub fn window_mesh(&self, n: usize, i0: usize, j0: usize) -> Mesh {
        Mesh::grid(n, self.spacing, |a, b| self.rest(i0 + a, j0 + b))
    }
}
