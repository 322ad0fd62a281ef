//! The shape of a tissue's rest surface, as a type that owns its geometry: [`Flat`] (its
//! normal the constant `z`: nothing to compute per tick) or [`Cap`] (a spherical cap,
//! `cap.rs`). A window ([`crate::Window`]) holds one, its shift moves what the shape
//! needs moved, and a proxy reads it; a window's type names its shape, so that a flat
//! window's tick compiles without a curved shape's code. A window's shape is built at
//! start-up from a [`ShapeSpec`]: [`Flat`], or a [`Sphere`] of a radius. A rest surface
//! that a scene sends later (a height field) is one more [`Shape`].

mod cap;

pub(crate) use cap::N16_SH;
pub use cap::{Cap, MAX_CAP_RADIUS_MM};

/// The shape of a tissue's rest surface: [`Flat`] or [`Cap`] (sealed: the core's
/// window and proxy know each one's geometry).
pub trait Shape: Copy + core::fmt::Debug + PartialEq + Eq + sealed::Sealed {
    /// The rest heights of a window's surface nodes as the proxy reads them: none for a
    /// flat tissue (every one is 0, a constant), the window's own on a curved one.
    #[doc(hidden)]
    type Rest<'a>: RestHeights + Copy;

    /// The cap this shape is, if it is one: the one question the window and the proxy
    /// ask of a shape. [`Flat`]'s `None` is known where it is compiled, so a flat
    /// window's tick carries none of a cap's code.
    #[doc(hidden)]
    fn cap(&self) -> Option<&Cap>;

    /// Its rest heights from a window's (node `(a, b)` of an `n × n` window at
    /// `a n + b`).
    #[doc(hidden)]
    fn rest<'a>(&self, heights: &'a [i32]) -> Self::Rest<'a>;
}

/// The rest height of a window's surface node `(a, b)` at index `a n + b` (Q24 mm).
#[doc(hidden)]
pub trait RestHeights {
    /// Node `i`'s rest height.
    fn z(&self, i: usize) -> i32;
}

/// A flat tissue's rest heights: every one 0.
#[doc(hidden)]
#[derive(Clone, Copy, Debug)]
pub struct Level;

impl RestHeights for Level {
    #[inline(always)]
    fn z(&self, _: usize) -> i32 {
        0
    }
}

impl RestHeights for &[i32] {
    #[inline(always)]
    fn z(&self, i: usize) -> i32 {
        self.get(i).copied().unwrap_or(0)
    }
}

/// A flat tissue, its top at `z = 0`: as a [`Shape`] and as its own [`ShapeSpec`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Flat;

impl Shape for Flat {
    type Rest<'a> = Level;

    #[inline(always)]
    fn cap(&self) -> Option<&Cap> {
        None
    }

    #[inline(always)]
    fn rest(&self, _: &[i32]) -> Level {
        Level
    }
}

impl Shape for Cap {
    type Rest<'a> = &'a [i32];

    #[inline(always)]
    fn cap(&self) -> Option<&Cap> {
        Some(self)
    }

    #[inline(always)]
    fn rest<'a>(&self, heights: &'a [i32]) -> &'a [i32] {
        heights
    }
}

/// What a window's [`Shape`] is built from (start-up), for a `w × h` tissue at `spacing`
/// mm whose arithmetic takes springs up to `max_rest_length_mm`.
pub trait ShapeSpec {
    /// The shape it builds.
    type Shape: Shape;
    /// The shape; `None` where the core cannot run it (the window then refuses it with
    /// `ProxyError::Cap`).
    fn shape(
        &self,
        w: usize,
        h: usize,
        spacing: f64,
        max_rest_length_mm: f64,
    ) -> Option<Self::Shape>;
}

impl ShapeSpec for Flat {
    type Shape = Flat;
    fn shape(&self, _: usize, _: usize, _: f64, _: f64) -> Option<Flat> {
        Some(Flat)
    }
}

/// A tissue shaped as a spherical cap of `radius_mm` (4/3 of the tissue's half-diagonal …
/// 2000 mm; its top at the tissue's centre at `z = 0`): builds a [`Cap`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// The sphere's radius, mm.
    pub radius_mm: f64,
}

impl ShapeSpec for Sphere {
    type Shape = Cap;

    /// The cap, if the core can run it: its radius in range, its base above −100 mm and
    /// its longest spring (at the tissue's corner) within the arithmetic's.
    fn shape(&self, w: usize, h: usize, s: f64, max_rest_length_mm: f64) -> Option<Cap> {
        let r = self.radius_mm;
        let cap = Cap::new(r, w, h, s)?;
        let (hx, hy) = ((w as f64 - 1.0) * s / 2.0, (h as f64 - 1.0) * s / 2.0);
        let z = |x: f64, y: f64| libm::sqrt(r * r - x * x - y * y) - r;
        // The steepest cell is the corner's: its diagonal is the longest spring.
        let dz = z(hx, hy) - z(hx - s, hy - s);
        let longest = libm::sqrt(2.0 * s * s + dz * dz);
        (z(hx, hy) - s >= -100.0 && longest <= max_rest_length_mm).then_some(cap)
    }
}

mod sealed {
    /// Only the core's shapes are [`super::Shape`]s.
    pub trait Sealed {}
    impl Sealed for super::Flat {}
    impl Sealed for super::Cap {}
}
