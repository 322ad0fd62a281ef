//! The tissue's surface as triangles, and points on it held in surface coordinates.
//!
//! Each grid cell `(i, j)`–`(i+1, j+1)` is split along its diagonal `(i, j)`–`(i+1, j+1)`
//! into a lower triangle `(i, j), (i+1, j), (i+1, j+1)` and an upper one `(i, j),
//! (i+1, j+1), (i, j+1)`, both wound so that their normal points up. A point on the
//! surface is an [`Anchor`]: a triangle and barycentric weights, so that it moves with the
//! deformed nodes and survives a window shift.

use super::tissue::Tissue;
use crate::patch::V;

/// A point on the surface: a triangle of the tissue grid and barycentric weights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Anchor {
    /// The cell's first corner, tissue grid coordinates.
    pub cell: (usize, usize),
    /// The upper triangle of the cell (else the lower).
    pub upper: bool,
    /// Weights of the triangle's corners (sum 1, each ≥ 0).
    pub bary: [f64; 3],
}

impl Anchor {
    /// The triangle's corners, tissue grid coordinates.
    pub fn corners(&self) -> [(usize, usize); 3] {
        let (i, j) = self.cell;
        if self.upper {
            [(i, j), (i + 1, j + 1), (i, j + 1)]
        } else {
            [(i, j), (i + 1, j), (i + 1, j + 1)]
        }
    }

    /// The point, from the corners' current positions.
    pub fn point(&self, pos: impl Fn((usize, usize)) -> V) -> V {
        let c = self.corners().map(&pos);
        [0, 1, 2].map(|k| (0..3).map(|m| self.bary[m] * c[m][k]).sum())
    }

    /// The triangle's upward unit normal, from the corners' current positions.
    pub fn normal(&self, pos: impl Fn((usize, usize)) -> V) -> V {
        let [p0, p1, p2] = self.corners().map(&pos);
        let (e1, e2) = (sub(p1, p0), sub(p2, p0));
        let n = [
            e1[1] * e2[2] - e1[2] * e2[1],
            e1[2] * e2[0] - e1[0] * e2[2],
            e1[0] * e2[1] - e1[1] * e2[0],
        ];
        let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        if l > 0.0 {
            n.map(|x| x / l)
        } else {
            [0.0, 0.0, 1.0]
        }
    }

    /// Continuous grid coordinates of the point (in the rest grid).
    pub fn grid(&self) -> (f64, f64) {
        let c = self.corners();
        let u = (0..3).map(|m| self.bary[m] * c[m].0 as f64).sum();
        let v = (0..3).map(|m| self.bary[m] * c[m].1 as f64).sum();
        (u, v)
    }
}

fn sub(a: V, b: V) -> V {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// Barycentric weights of `(x, y)` in the `xy` projection of a triangle (`None` if it is
/// degenerate there).
fn bary_xy(p: [V; 3], x: f64, y: f64) -> Option<[f64; 3]> {
    let d = (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]);
    if d.abs() < 1e-12 {
        return None;
    }
    let b1 = ((x - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (y - p[0][1])) / d;
    let b2 = ((p[1][0] - p[0][0]) * (y - p[0][1]) - (x - p[0][0]) * (p[1][1] - p[0][1])) / d;
    Some([1.0 - b1 - b2, b1, b2])
}

/// The surface point above or below `(x, y)` (mm) on the deformed surface whose nodes are
/// at `pos`: the triangle whose `xy` projection holds it, searched among the 3 × 3 cells
/// around the rest grid's guess (nodes move less than a spacing sideways). Beyond the
/// tissue's edge, the point above the nearest point of its rectangle (`(x, y)` clamped
/// to the rest extent, as the core clamps the grid point: the edge's nodes are fixed).
pub fn locate(tissue: &Tissue, pos: impl Fn((usize, usize)) -> V, x: f64, y: f64) -> Anchor {
    let (hx, hy) = tissue.half_extent();
    let (x, y) = (x.clamp(-hx, hx), y.clamp(-hy, hy));
    let (u, v) = tissue.grid(x, y);
    let clamp = |g: f64, n: usize| (g.floor().max(0.0) as usize).min(n - 2);
    let (ci, cj) = (clamp(u, tissue.w), clamp(v, tissue.h));
    let mut best: Option<(f64, Anchor)> = None;
    for i in ci.saturating_sub(1)..=(ci + 1).min(tissue.w - 2) {
        for j in cj.saturating_sub(1)..=(cj + 1).min(tissue.h - 2) {
            for upper in [false, true] {
                let a = Anchor {
                    cell: (i, j),
                    upper,
                    bary: [1.0, 0.0, 0.0],
                };
                let Some(b) = bary_xy(a.corners().map(&pos), x, y) else {
                    continue;
                };
                let inside = b[0].min(b[1]).min(b[2]);
                if best.as_ref().is_none_or(|(m, _)| inside > *m) {
                    best = Some((inside, Anchor { bary: b, ..a }));
                }
            }
        }
    }
    let (_, mut a) = best.unwrap_or((
        0.0,
        Anchor {
            cell: (ci, cj),
            upper: false,
            bary: [1.0, 0.0, 0.0],
        },
    ));
    // On the edge, or a rounding outside the triangle: the weights clipped to it.
    let clipped = a.bary.map(|b| b.max(0.0));
    let sum: f64 = clipped.iter().sum();
    a.bary = clipped.map(|b| b / sum);
    a
}
