//! The maths backend, and the one door to float maths: the kernel calls
//! `math::atan2(y, x)`, never methods such as `y.atan2(x)`, so the host build and the
//! target build use the same backend. (With `std` linked into host tests, method syntax
//! would silently call std's maths while the target uses micromath, and the two builds
//! would disagree.)
//!
//! # Backends
//!
//! | feature | atan2 | sin / cos | bits |
//! |---|---|---|---|
//! | `libm` (default) | ≤ 2 ulp (`atan2_octant`) | ≤ 1 ulp | identical on x86-64 and Cortex-M4F |
//! | `micromath` | within about 0.16° | about 1.1e-3 | approximate |
//!
//! # Which backend runs
//!
//! **The `micromath` feature selects micromath; without it, libm runs.** [`BACKEND`] says
//! which, for programs to print (`curbtrace kernel` does).
//!
//! Cargo features are additive and `libm` is a default feature, so `--features micromath`
//! alone builds both backends. That build is not an error, because it is the one the tests
//! need: with both compiled in, the micromath tolerance test runs the same lines through
//! both and compares them, while everything else (the kernel, the other tests) uses
//! micromath. A product build that wants micromath says
//! `--no-default-features --features micromath` (the firmware's micromath build does), and
//! libm is then not compiled at all. With neither feature the crate does not compile.
//!
//! The kernel's hot path uses only `atan2` (once per kept point, for the output ρ);
//! thresholds are compared without it (see `kernel::bend`).

/// A maths backend of the core (see the module docs for the rule that picks one).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Backend {
    /// `libm`: bit-exact, portable; the same output bytes on every platform.
    Libm,
    /// `micromath`: fast, approximate.
    Micromath,
}

impl Backend {
    /// The backend's name, as its Cargo feature spells it.
    pub const fn name(self) -> &'static str {
        match self {
            Backend::Libm => "libm",
            Backend::Micromath => "micromath",
        }
    }
}

impl core::fmt::Display for Backend {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.name())
    }
}

/// The backend this build of the core computes with: micromath when its feature is on,
/// otherwise libm.
pub const BACKEND: Backend = if cfg!(feature = "micromath") {
    Backend::Micromath
} else {
    Backend::Libm
};

#[cfg(not(any(feature = "libm", feature = "micromath")))]
compile_error!(
    "curbtrace-core needs a maths backend: enable feature `libm` (the default) or `micromath`"
);

/// The functions of a backend. The kernel is generic over it only so that a test build with
/// both features can run the same line through both (the micromath tolerance test);
/// everything else calls the free functions below.
pub(crate) trait Maths {
    /// Four-quadrant arctangent of `y / x`, radians in [−π, π]; +0 for x = y = ±0 (the
    /// bend angle relies on it).
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
impl Maths for Libm {
    #[inline]
    fn atan2(y: f32, x: f32) -> f32 {
        atan2_octant(y, x)
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

/// Four-quadrant arctangent from `libm::atanf` on the first octant: q = min(|y|, |x|) /
/// max(|y|, |x|) ∈ [0, 1], a = atan q, then a, π/2 − a, π − a by octant and the sign of y.
///
/// The textbook reduction, and cheaper than `libm::atan2f` on the kernel's arguments
/// (finite: the kernel sets non-finite and out-of-range points aside first): atan2f's
/// special-case tests for NaN, infinities, zeros and extreme ratios go (x = y = 0 is one
/// test here, and gives +0, which the bend angle relies on), and atanf always gets an
/// argument ≤ 1, its short path (no reciprocal); on the Cortex-M4F that is fewer
/// instructions per input point (docs/benchmarks.md). Every step is an IEEE-754 f32
/// operation or `libm::atanf`, so the host and the M4F agree bit for bit. Accuracy: atanf's
/// 1 ulp plus one rounded subtraction — within 2 ulp of the true angle (tested against f64
/// over every octant). At y = ±0 it gives +0 or π (atan2f: ±0 or ±π); x = y = 0 gives 0.
#[cfg(feature = "libm")]
#[cfg_attr(feature = "micromath", allow(dead_code))]
#[inline(always)]
pub(crate) fn atan2_octant(y: f32, x: f32) -> f32 {
    use core::f32::consts::{FRAC_PI_2, PI};
    let (ay, ax) = (abs(y), abs(x));
    let steep = ay > ax;
    let (num, den) = if steep { (ax, ay) } else { (ay, ax) };
    if den == 0.0 {
        return 0.0;
    }
    let mut a = libm::atanf(num / den);
    if steep {
        a = FRAC_PI_2 - a;
    }
    if x < 0.0 {
        a = PI - a;
    }
    if y < 0.0 {
        -a
    } else {
        a
    }
}

/// micromath: fast, approximate.
#[cfg(feature = "micromath")]
pub(crate) struct Micromath;

#[cfg(feature = "micromath")]
impl Maths for Micromath {
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

/// The backend in force ([`BACKEND`]; micromath when both features are on).
#[cfg(feature = "micromath")]
pub(crate) type Selected = Micromath;
/// The backend in force ([`BACKEND`]).
#[cfg(all(feature = "libm", not(feature = "micromath")))]
pub(crate) type Selected = Libm;

/// Four-quadrant arctangent of `y / x`, radians.
#[inline]
#[allow(dead_code)] // the kernel calls it through `Maths`; kept as the documented door
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
        for (y, x) in [(0.0f32, 0.0f32), (-0.0, 0.0), (0.0, -0.0), (-0.0, -0.0)] {
            assert_eq!(atan2(y, x).to_bits(), 0, "atan2({y}, {x}) is +0");
        }
        assert!((cos(core::f32::consts::FRAC_PI_3) - 0.5).abs() < 2e-3);
        assert!((sin(core::f32::consts::FRAC_PI_6) - 0.5).abs() < 2e-3);
        assert_eq!(abs(-2.5), 2.5);
        assert_eq!(abs(2.5), 2.5);
        assert_eq!(abs(-0.0).to_bits(), 0);
    }

    /// Distance in ulps between two finite f32 of the same sign.
    #[cfg(feature = "libm")]
    fn ulps(a: f32, b: f32) -> u32 {
        (a.to_bits() as i64 - b.to_bits() as i64).unsigned_abs() as u32
    }

    #[cfg(feature = "libm")]
    #[test]
    fn octant_atan2_is_within_2_ulp_of_f64_in_every_octant() {
        extern crate std;
        let mut r = 99u64;
        let mut u = || {
            r = r
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((r >> 40) as f32) / ((1u64 << 24) as f32)
        };
        let mut worst = 0;
        for k in 0..400_000 {
            // Magnitudes from 1e-12 to 1e12 and every sign combination.
            let m = |v: f32| libm::powf(10.0, 24.0 * v - 12.0);
            let y = m(u()) * if k % 2 == 0 { 1.0 } else { -1.0 };
            let x = m(u()) * if k % 4 < 2 { 1.0 } else { -1.0 };
            let got = atan2_octant(y, x);
            let want = (f64::from(y)).atan2(f64::from(x)) as f32;
            worst = worst.max(ulps(got, want));
            assert!(
                ulps(got, want) <= 2,
                "atan2({y}, {x}) = {got}, f64 says {want}"
            );
            // The kernel's libm path agrees with libm's own atan2f to 2 ulp too.
            assert!(ulps(got, libm::atan2f(y, x)) <= 2, "{y} {x}");
        }
        assert!(worst >= 1, "the test would see a difference");
        // Axes and diagonals.
        assert_eq!(atan2_octant(0.0, 0.0), 0.0);
        assert_eq!(atan2_octant(0.0, -2.0), core::f32::consts::PI);
        assert_eq!(atan2_octant(-3.0, 0.0), -core::f32::consts::FRAC_PI_2);
        assert_eq!(
            atan2_octant(-1.0, -1.0),
            -3.0 * core::f32::consts::FRAC_PI_4
        );
    }

    /// [`BACKEND`] names the backend the free functions use.
    #[test]
    fn backend_constant_names_the_backend_in_force() {
        extern crate std;
        use std::string::ToString;
        let probe = [(0.3f32, 0.7f32), (1.0, 1.0), (-2.0, 0.5)];
        for (y, x) in probe {
            let got = atan2(y, x).to_bits();
            match BACKEND {
                #[cfg(feature = "libm")]
                Backend::Libm => assert_eq!(got, Libm::atan2(y, x).to_bits()),
                #[cfg(feature = "micromath")]
                Backend::Micromath => assert_eq!(got, Micromath::atan2(y, x).to_bits()),
                #[allow(unreachable_patterns)]
                other => panic!("{other} is not compiled into this build"),
            }
        }
        // With both compiled in, the probe tells them apart, so the match above is a test.
        #[cfg(all(feature = "libm", feature = "micromath"))]
        assert!(probe
            .iter()
            .any(|&(y, x)| Libm::atan2(y, x) != Micromath::atan2(y, x)));
        assert_eq!(
            BACKEND,
            if cfg!(feature = "micromath") {
                Backend::Micromath
            } else {
                Backend::Libm
            }
        );
        assert_eq!(BACKEND.to_string(), BACKEND.name());
    }

    #[cfg(all(feature = "libm", not(feature = "micromath")))]
    #[test]
    fn libm_is_exact_at_simple_angles() {
        assert_eq!(atan2(1.0, 1.0), core::f32::consts::FRAC_PI_4);
        assert_eq!(atan2(1.0, 0.0), core::f32::consts::FRAC_PI_2);
        assert_eq!(atan2(0.0, -1.0), core::f32::consts::PI);
    }
}
