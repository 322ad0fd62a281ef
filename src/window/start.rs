//! A window's start-up: where it is placed, and the maps its shifts read (which spring
//! each spring continues in each direction), from where every spring's ends are on the
//! patch's grid.

use super::{pack_ends, Window, FLIP, NONE};
use crate::proxy::ProxyError;
use crate::q::{mul_wide, sat};
use crate::shape::Shape;
use crate::units::from_f64;

/// Where a spring's end is on the patch's grid: `(a, b, layer)` (layer 1: the base).
pub(crate) type Key = [i32; 3];

/// The shift directions, in the order of [`Window`]'s maps.
pub(crate) const DIRECTIONS: [[i32; 2]; 4] = [[1, 0], [-1, 0], [0, 1], [0, -1]];

/// Where a window goes on its tissue, its configuration checked (`Solver::window`).
pub(crate) struct Placement {
    /// The patch's side, the tissue's width and height (nodes).
    pub n: usize,
    pub w: usize,
    pub h: usize,
    /// The spacing, mm and Q24 mm.
    pub s: f64,
    pub spacing: i32,
    /// The window's corner on the tissue (nodes).
    pub corner: [i32; 2],
    /// The shift threshold, Q16 spacings.
    pub limit: i32,
}

impl<const EDGES: usize, Sh: Shape> Window<EDGES, Sh> {
    /// The window at `place` on a tissue of `shape`, for a patch whose first `count`
    /// springs have their ends at `keys`: its maps and, on a cap, its rest heights. A cap
    /// needs every spring's source on one side of it per direction (its shift moves the
    /// springs' geometry in place: forwards along +x and +y, backwards along −x and −y;
    /// the standard patch's springs are laid out cell by cell, so this holds): a
    /// topology for which it does not is refused ([`ProxyError::Grid`]), as is a window
    /// whose heights do not fit ([`ProxyError::Window`]).
    pub(crate) fn at(
        place: &Placement,
        shape: Sh,
        keys: &[[Key; 2]; EDGES],
        count: usize,
    ) -> Result<Self, ProxyError> {
        // A map entry is a spring's index below `FLIP`, and `NONE`'s index names none.
        const { assert!(EDGES < (NONE & !FLIP) as usize) };
        let maps = DIRECTIONS.map(|d| {
            core::array::from_fn(|e| {
                if e >= count {
                    return NONE;
                }
                let moved = keys[e].map(|k| [k[0] + d[0], k[1] + d[1], k[2]]);
                (0..count)
                    .find_map(|o| {
                        let k = keys[o];
                        if k[0] == moved[0] && k[1] == moved[1] {
                            Some(o as u16)
                        } else if k[0] == moved[1] && k[1] == moved[0] {
                            Some(o as u16 | FLIP)
                        } else {
                            None
                        }
                    })
                    .unwrap_or(NONE)
            })
        });
        let ordered = || {
            maps.iter()
                .enumerate()
                .all(|(dir, map): (usize, &[u16; EDGES])| {
                    map.iter().enumerate().all(|(e, &m)| {
                        let (source, _) = super::continued(m);
                        m == NONE || (dir % 2 == 0 && source > e) || (dir % 2 == 1 && source < e)
                    })
                })
        };
        let cap = shape.cap().copied();
        if cap.is_some() && !ordered() {
            return Err(ProxyError::Grid);
        }
        let &Placement {
            n,
            w,
            h,
            s,
            spacing,
            corner,
            limit,
        } = place;
        let mut window = Window {
            n: n as i32,
            w: w as i32,
            h: h as i32,
            corner,
            limit,
            spacing,
            maps,
            shifts: 0,
            shape,
            inv_s: from_f64(1.0 / s, 30),
            half: [w, h].map(|k| sat(mul_wide(k as i32 - 1, spacing) >> 1)),
            heights: [0; EDGES],
            ends: core::array::from_fn(|e| pack_ends(keys[e])),
        };
        if let Some(cap) = cap {
            window.fill_heights(&cap).ok_or(ProxyError::Window)?;
        }
        Ok(window)
    }
}
