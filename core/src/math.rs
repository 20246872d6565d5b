//! The one door to float maths (STYLE.md): call `math::atan2(y, x)`, never methods, so the
//! host build and the target build use the same backend. With `std` linked into host tests,
//! `x.atan2(y)` would silently call std's maths while the target uses micromath, and the two
//! builds would disagree.
//!
//! Backends, chosen by feature:
//!
//! | feature | atan2 | sin / cos | bits |
//! |---|---|---|---|
//! | `libm` (default) | ≤ 1 ulp | ≤ 1 ulp | identical on x86-64 and Cortex-M4F |
//! | `micromath` | max error 0.162° (TOOLCHAIN.md, 1e6 samples) | about 1.1e-3 | approximate |
//!
//! When both features are enabled (`--features micromath` keeps the default `libm`),
//! **micromath wins**: asking for it is an explicit choice, the default is not. With
//! neither, the crate does not compile.
//!
//! The kernel's hot path uses only [`atan2`] (once per kept point, for the output ρ);
//! thresholds are compared without it (see `kernel::bend`).

#[cfg(not(any(feature = "libm", feature = "micromath")))]
compile_error!(
    "curbtrace-core needs a maths backend: enable feature `libm` (the default) or `micromath`"
);

/// A float backend. The kernel is generic over it only so that a test build with both
/// features can run the same line through both (the micromath tolerance test); everything
/// else calls the free functions below.
pub(crate) trait Backend {
    /// Four-quadrant arctangent of `y / x`, radians in (−π, π].
    fn atan2(y: f32, x: f32) -> f32;
    /// Sine of `x` radians.
    fn sin(x: f32) -> f32;
    /// Cosine of `x` radians.
    fn cos(x: f32) -> f32;
}

/// libm: bit-exact, portable (the default).
#[cfg(feature = "libm")]
#[cfg_attr(feature = "micromath", allow(dead_code))] // then only the tolerance test uses it
pub(crate) struct Libm;

#[cfg(feature = "libm")]
impl Backend for Libm {
    #[inline]
    fn atan2(y: f32, x: f32) -> f32 {
        libm::atan2f(y, x)
    }
    #[inline]
    fn sin(x: f32) -> f32 {
        libm::sinf(x)
    }
    #[inline]
    fn cos(x: f32) -> f32 {
        libm::cosf(x)
    }
}

/// micromath: fast, approximate.
#[cfg(feature = "micromath")]
pub(crate) struct Micromath;

#[cfg(feature = "micromath")]
impl Backend for Micromath {
    #[inline]
    fn atan2(y: f32, x: f32) -> f32 {
        // micromath divides by x² + |bxy| + n, which is 0 at the origin; libm gives 0 there.
        if x == 0.0 && y == 0.0 {
            return 0.0;
        }
        micromath::F32(y).atan2(micromath::F32(x)).0
    }
    #[inline]
    fn sin(x: f32) -> f32 {
        micromath::F32(x).sin().0
    }
    #[inline]
    fn cos(x: f32) -> f32 {
        micromath::F32(x).cos().0
    }
}

/// The backend in force (micromath when both features are on; see the module docs).
#[cfg(feature = "micromath")]
pub(crate) type Selected = Micromath;
/// The backend in force (micromath when both features are on; see the module docs).
#[cfg(all(feature = "libm", not(feature = "micromath")))]
pub(crate) type Selected = Libm;

/// Four-quadrant arctangent of `y / x`, radians.
#[inline]
#[allow(dead_code)] // the kernel calls it through `Backend`; kept as the documented door
pub(crate) fn atan2(y: f32, x: f32) -> f32 {
    Selected::atan2(y, x)
}

/// Sine of `x` radians.
#[inline]
pub(crate) fn sin(x: f32) -> f32 {
    Selected::sin(x)
}

/// Cosine of `x` radians.
#[inline]
pub(crate) fn cos(x: f32) -> f32 {
    Selected::cos(x)
}

/// |x| by clearing the sign bit (no backend needed; core's `f32::abs` is not available
/// on every toolchain this crate builds with).
#[inline]
pub(crate) fn abs(x: f32) -> f32 {
    f32::from_bits(x.to_bits() & 0x7fff_ffff)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hand_checked_values() {
        let deg = 180.0 / core::f32::consts::PI;
        assert!((atan2(1.0, 0.0) * deg - 90.0).abs() < 0.2);
        assert!((atan2(1.0, 1.0) * deg - 45.0).abs() < 0.2);
        assert!((atan2(-1.0, -1.0) * deg + 135.0).abs() < 0.2);
        assert_eq!(atan2(0.0, 0.0), 0.0);
        assert!((cos(core::f32::consts::FRAC_PI_3) - 0.5).abs() < 2e-3);
        assert!((sin(core::f32::consts::FRAC_PI_6) - 0.5).abs() < 2e-3);
        assert_eq!(abs(-2.5), 2.5);
        assert_eq!(abs(2.5), 2.5);
        assert_eq!(abs(-0.0).to_bits(), 0);
    }

    #[cfg(all(feature = "libm", not(feature = "micromath")))]
    #[test]
    fn libm_is_exact_at_simple_angles() {
        assert_eq!(atan2(1.0, 1.0), core::f32::consts::FRAC_PI_4);
        assert_eq!(atan2(1.0, 0.0), core::f32::consts::FRAC_PI_2);
        assert_eq!(atan2(0.0, -1.0), core::f32::consts::PI);
    }
}
