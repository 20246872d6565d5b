//! [`KernelParams`]: every parameter of the kernel (and of scanline assembly), with
//! defaults, carried in the stream's config packet as [`CONFIG_WORDS`] little-endian words.
//!
//! # Config words
//!
//! | word | field | encoding | accepted range |
//! |---|---|---|---|
//! | 0 | [`KernelParams::d_b_m`] | f32 bits | (0, 10] |
//! | 1 | [`KernelParams::irregular_deg`] | f32 bits | (0, 180] |
//! | 2 | [`KernelParams::tau_min_deg`] | f32 bits | [0, 180) |
//! | 3 | [`KernelParams::tau_max_deg`] | f32 bits | (τ_min, 180] |
//! | 4 | [`KernelParams::taubin_steps`] | u32 | 0..=200 |
//! | 5 | [`KernelParams::taubin_lambda`] | f32 bits | (0, 1] |
//! | 6 | [`KernelParams::taubin_mu`] | f32 bits | [−1, 0) |
//! | 7 | [`KernelParams::smooth_gap_m`] | f32 bits | [0, 100] |
//! | 8 | [`KernelParams::split_gap_ns`] | u32 | any |
//! | 9 | [`KernelParams::split_geometry`] | u32 | 0 = auto, 1 = always, 2 = never |
//! | 10 | [`KernelParams::roi_x_min_m`] | f32 bits | [−2000, 2000]; see below |
//! | 11 | [`KernelParams::roi_x_max_m`] | f32 bits | (roi_x_min_m, 2000] |
//! | 12 | [`KernelParams::roi_z_min_m`] | f32 bits | [−2000, 2000] |
//! | 13 | [`KernelParams::roi_z_max_m`] | f32 bits | (roi_z_min_m, 2000] |
//! | 14 | [`KernelParams::output_mode`] | u32 | 0 = points, 1 = candidates |
//! | 15 | reserved | 0 | 0 |
//!
//! Words 10–14 are wire-format version 2 (a config packet that sets one is a version-2
//! packet). The region of interest is off when words 10–13 are all zero; otherwise it is
//! the box `roi_x_min_m ≤ x′ ≤ roi_x_max_m`, `roi_z_min_m ≤ z′ ≤ roi_z_max_m`, both
//! extents positive.
//!
//! NaN and infinities are out of range for every f32 word. The words round-trip exactly
//! (`from_words(p.to_words()) == Ok(p)`), and [`KernelParams::hash`] is FNV-1a over their
//! little-endian bytes, so the same words always give the same hash on every platform.

use crate::scanline::assemble::{GeometrySplit, SplitParams};
use crate::wire::CONFIG_WORDS;

/// One field of [`KernelParams`], named as in the `[kernel]` table of the host's config
/// file; the discriminant is the field's config word.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u8)]
pub enum Param {
    /// [`KernelParams::d_b_m`].
    DBM = 0,
    /// [`KernelParams::irregular_deg`].
    IrregularDeg = 1,
    /// [`KernelParams::tau_min_deg`].
    TauMinDeg = 2,
    /// [`KernelParams::tau_max_deg`].
    TauMaxDeg = 3,
    /// [`KernelParams::taubin_steps`].
    TaubinSteps = 4,
    /// [`KernelParams::taubin_lambda`].
    TaubinLambda = 5,
    /// [`KernelParams::taubin_mu`].
    TaubinMu = 6,
    /// [`KernelParams::smooth_gap_m`].
    SmoothGapM = 7,
    /// [`KernelParams::split_gap_ns`].
    SplitGapNs = 8,
    /// [`KernelParams::split_geometry`].
    SplitGeometry = 9,
    /// [`KernelParams::roi_x_min_m`].
    RoiXMinM = 10,
    /// [`KernelParams::roi_x_max_m`].
    RoiXMaxM = 11,
    /// [`KernelParams::roi_z_min_m`].
    RoiZMinM = 12,
    /// [`KernelParams::roi_z_max_m`].
    RoiZMaxM = 13,
    /// [`KernelParams::output_mode`].
    OutputMode = 14,
}

impl Param {
    /// Every parameter, in word order.
    pub const ALL: [Param; 15] = [
        Param::DBM,
        Param::IrregularDeg,
        Param::TauMinDeg,
        Param::TauMaxDeg,
        Param::TaubinSteps,
        Param::TaubinLambda,
        Param::TaubinMu,
        Param::SmoothGapM,
        Param::SplitGapNs,
        Param::SplitGeometry,
        Param::RoiXMinM,
        Param::RoiXMaxM,
        Param::RoiZMinM,
        Param::RoiZMaxM,
        Param::OutputMode,
    ];

    /// Index of the parameter's config word.
    pub const fn word(self) -> usize {
        self as usize
    }

    /// The field's name (also its key in the host's `[kernel]` table).
    pub const fn name(self) -> &'static str {
        match self {
            Param::DBM => "d_b_m",
            Param::IrregularDeg => "irregular_deg",
            Param::TauMinDeg => "tau_min_deg",
            Param::TauMaxDeg => "tau_max_deg",
            Param::TaubinSteps => "taubin_steps",
            Param::TaubinLambda => "taubin_lambda",
            Param::TaubinMu => "taubin_mu",
            Param::SmoothGapM => "smooth_gap_m",
            Param::SplitGapNs => "split_gap_ns",
            Param::SplitGeometry => "split_geometry",
            Param::RoiXMinM => "roi_x_min_m",
            Param::RoiXMaxM => "roi_x_max_m",
            Param::RoiZMinM => "roi_z_min_m",
            Param::RoiZMaxM => "roi_z_max_m",
            Param::OutputMode => "output_mode",
        }
    }

    /// The accepted values, as in the module's table: `(`/`)` exclude the bound, `[`/`]`
    /// include it; `a..=b` is an integer range. NaN and infinities are never accepted.
    pub const fn range(self) -> &'static str {
        match self {
            Param::DBM => "(0, 10]",
            Param::IrregularDeg => "(0, 180]",
            Param::TauMinDeg => "[0, 180)",
            Param::TauMaxDeg => "(tau_min_deg, 180]",
            Param::TaubinSteps => "0..=200",
            Param::TaubinLambda => "(0, 1]",
            Param::TaubinMu => "[-1, 0)",
            Param::SmoothGapM => "[0, 100]",
            Param::SplitGapNs => "any u32",
            Param::SplitGeometry => "0..=2 (0 = auto, 1 = always, 2 = never)",
            Param::RoiXMinM => "[-2000, 2000] (all four roi_* 0 = no region)",
            Param::RoiXMaxM => "(roi_x_min_m, 2000] (all four roi_* 0 = no region)",
            Param::RoiZMinM => "[-2000, 2000] (all four roi_* 0 = no region)",
            Param::RoiZMaxM => "(roi_z_min_m, 2000] (all four roi_* 0 = no region)",
            Param::OutputMode => "0..=1 (0 = points, 1 = candidates)",
        }
    }

    /// Whether the word holds f32 bits (otherwise a `u32`).
    pub const fn is_f32(self) -> bool {
        !matches!(
            self,
            Param::TaubinSteps | Param::SplitGapNs | Param::SplitGeometry | Param::OutputMode
        )
    }
}

/// Why a config block was rejected. Two bytes: the pipeline keeps the last one in its
/// counters, which the firmware updates per line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum ParamsError {
    /// A parameter is NaN, infinite or outside its range ([`Param::range`]).
    OutOfRange {
        /// The parameter.
        param: Param,
    },
    /// A reserved word is not zero.
    ReservedNotZero {
        /// Index of the word.
        index: u8,
    },
}

impl core::fmt::Display for ParamsError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            ParamsError::OutOfRange { param } => {
                let what = if param.is_f32() {
                    "NaN, infinite or outside its range"
                } else {
                    "outside its range"
                };
                write!(f, "{} is {what} {}", param.name(), param.range())
            }
            ParamsError::ReservedNotZero { index } => {
                write!(f, "config word {index} is reserved and must be 0")
            }
        }
    }
}

impl core::error::Error for ParamsError {}

/// Every parameter of the kernel (Honma et al. §2.3–2.6) and of scanline assembly
/// (docs/spec.md §2, *Scanline*), so that one config packet configures the whole core.
///
/// The paper gives the Taubin values (§2.5) and nothing else numerically; every other
/// default below says how it was chosen. The target is a VQ-250-class line (Honma et al.
/// Table 1): about 10 mm point spacing on the road near the scanner, about 35 mm at 5 m,
/// up to about 140 mm at the far curb; curbs 80–200 mm high; curb cuts 20–30 mm steps.
///
/// With the `serde` feature it (de)serialises as a table of its fields under their own
/// names; missing fields take their defaults and unknown ones are rejected, so a typo does
/// not silently leave a default in force. Deserialising does not check ranges: call
/// [`Self::validate`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct KernelParams {
    /// d_b: neighbour distance for the bend angle, metres (§2.3: s and t are the farthest
    /// points within d_b of p_i, walking outward along the scanline).
    ///
    /// Default 0.07 m — not given by the paper. Chosen to stay below the height of the
    /// lowest common curbs (80 mm): with d_b < h the toe of a step is a sharp +90° peak (s on
    /// the road, t on the face), while with d_b > h the far neighbour lands on the curb top
    /// for every road point within √(d_b² − h²) of the toe and ρ forms a plateau of
    /// asin(h/d_b) there, which lets noise place the peak anywhere on it. On the synthetic
    /// scanline of `kernel::tests` (5 mm noise), 0.07 m puts the candidates of 80 mm curbs
    /// nearer the toe than 0.10 m or 0.13 m do; on 150 mm curbs the three agree. 0.07 m
    /// still spans 7 points at 10 mm spacing and 2 at 35 mm (5 m out), enough to average
    /// the noise. At the far curb (≈140 mm spacing) road points have no neighbour within
    /// d_b and get [`super::PointStatus::NoNeighbour`]; the host's tracking (§2.7) covers
    /// that side.
    pub d_b_m: f32,
    /// Threshold for the removal of irregular points, degrees (§2.4: points with |ρ| above
    /// it on the raw line are removed before smoothing).
    ///
    /// Default 120° — not given by the paper. It must stay well above 90°, or the raw toe
    /// and top of every curb (±90° plus noise) would be removed as irregular; 120° leaves
    /// 30° for noise on a sharp corner, and still removes spikes: a point sticking out more
    /// than sin(60°)·d_b ≈ 61 mm from a flat surface has |ρ| > 120° and goes (one sticking
    /// out more than d_b has no neighbour at all and is judged by its adjacent points, see
    /// `bend::mark_irregular`).
    pub irregular_deg: f32,
    /// τ_ρmin: lower bound (exclusive) of the bend angle of a peak, degrees (§2.6).
    ///
    /// Default 30° — not given by the paper ("close to 90 degrees"). Far below the toe of
    /// any curb taller than d_b (≈90°, somewhat less after smoothing rounds the corner),
    /// low enough for the toe of a 60–80 mm curb far from the scanner, where the returns
    /// lie farther apart than d_b and smoothing rounds the corner to 30–35°, yet well above
    /// road crown, ruts and the 5 mm noise left after smoothing (a few degrees; the
    /// synthetic lines of `kernel::tests` give no false candidate). Curb cuts (20–30 mm
    /// steps, ρ ≈ 17–25°) give no peak; the host tracks and bridges through them (§2.7).
    pub tau_min_deg: f32,
    /// τ_ρmax: upper bound (exclusive) of the bend angle of a peak, degrees (§2.6).
    ///
    /// Default 150° — not given by the paper. A toe seen from the road is about 90°; a
    /// thin spike that survived §2.4 can reach 180°. 150° keeps toes with some overhang or
    /// batter and drops needle-like returns.
    pub tau_max_deg: f32,
    /// Number of Taubin smoothing steps (§2.5: 20, chosen by the paper's experiment).
    pub taubin_steps: u32,
    /// Taubin scale factor of the even steps, λ (§2.5: 0.6307, after Taubin 1995).
    pub taubin_lambda: f32,
    /// Taubin scale factor of the odd steps, μ (§2.5: −0.6732, after Taubin 1995).
    pub taubin_mu: f32,
    /// Gap that splits the line for smoothing, metres: where two consecutive kept points
    /// are farther apart than this, the line is smoothed as separate pieces, each with its
    /// end points fixed (0 = never split).
    ///
    /// Default 0.30 m — an addition to the paper, which smooths the whole line. Across an
    /// occlusion shadow the next point can be metres away, and Taubin's step response
    /// would pull the points beside the gap towards it by centimetres, creating false
    /// bends; fixing both sides of a gap keeps the paper's "ends fixed" per visible piece.
    /// 0.30 m is twice the largest spacing expected on the road (≈140 mm at the far curb).
    pub smooth_gap_m: f32,
    /// Assembly (`scanline::assemble`, docs/spec.md §2 *Scanline*): a time step between
    /// consecutive points longer than this ends the line, nanoseconds.
    ///
    /// Default 5 ms — the assembler's own default ([`SplitParams::DEFAULT`]): half a
    /// revolution at 100 Hz; within a revolution points come every few µs.
    pub split_gap_ns: u32,
    /// Assembly: when the geometric split rule (side change away from the nadir) is active:
    /// 0 = until the stream's first line-start flag ([`GeometrySplit::Auto`], the default),
    /// 1 = always, 2 = never.
    pub split_geometry: u32,
    /// Region of interest, smallest x′ in metres (wire version 2). Points outside the box
    /// `roi_x_min_m..=roi_x_max_m` × `roi_z_min_m..=roi_z_max_m` are counted and get
    /// [`super::PointStatus::OutsideRoi`] with their raw coordinates; the kernel runs on the
    /// points inside as if the others were not there. All four `roi_*` 0 (the default): no
    /// region, every point is processed.
    ///
    /// A region is a deployment choice (the scanner's mounting, the lateral range where
    /// curbs are searched), not part of the method: the host's own extraction runs without
    /// one unless its config sets one.
    pub roi_x_min_m: f32,
    /// Region of interest, largest x′ in metres (see [`Self::roi_x_min_m`]).
    pub roi_x_max_m: f32,
    /// Region of interest, smallest z′ in metres (see [`Self::roi_x_min_m`]).
    pub roi_z_min_m: f32,
    /// Region of interest, largest z′ in metres (see [`Self::roi_x_min_m`]).
    pub roi_z_max_m: f32,
    /// What the core sends per line (wire version 2): 0 = output packets with every point
    /// (kind 3), 1 = a candidates packet only (kind 4: the nadir, both seed candidates and
    /// the counters). Default 0.
    pub output_mode: u32,
}

/// Index of the first reserved word.
const FIRST_RESERVED: usize = 15;

/// The largest |coordinate| of a region-of-interest bound, metres.
const ROI_LIMIT_M: f32 = 2000.0;

/// The region of interest of [`KernelParams`], when one is set.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Roi {
    /// Smallest x′, metres.
    pub x_min: f32,
    /// Largest x′, metres.
    pub x_max: f32,
    /// Smallest z′, metres.
    pub z_min: f32,
    /// Largest z′, metres.
    pub z_max: f32,
}

impl Roi {
    /// Whether (x′, z′) lies in the box (bounds included; NaN never does). The upper z′
    /// bound is tested first: most points outside a ground band lie above it (walls, trees).
    #[inline(always)]
    pub fn contains(&self, x: f32, z: f32) -> bool {
        z <= self.z_max && z >= self.z_min && x >= self.x_min && x <= self.x_max
    }
}

/// What the core sends per line ([`KernelParams::output_mode`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum OutputMode {
    /// Output packets with every point (kind 3).
    Points,
    /// One candidates packet per line (kind 4).
    Candidates,
}

impl KernelParams {
    /// The defaults (see each field for how its value was chosen).
    pub const DEFAULT: Self = Self {
        d_b_m: 0.07,
        irregular_deg: 120.0,
        tau_min_deg: 30.0,
        tau_max_deg: 150.0,
        taubin_steps: 20,
        taubin_lambda: 0.6307,
        taubin_mu: -0.6732,
        smooth_gap_m: 0.30,
        split_gap_ns: 5_000_000,
        split_geometry: 0,
        roi_x_min_m: 0.0,
        roi_x_max_m: 0.0,
        roi_z_min_m: 0.0,
        roi_z_max_m: 0.0,
        output_mode: 0,
    };

    /// The parameter block as config-packet words (see the module's table).
    pub fn to_words(&self) -> [u32; CONFIG_WORDS] {
        let mut w = [0u32; CONFIG_WORDS];
        w[0] = self.d_b_m.to_bits();
        w[1] = self.irregular_deg.to_bits();
        w[2] = self.tau_min_deg.to_bits();
        w[3] = self.tau_max_deg.to_bits();
        w[4] = self.taubin_steps;
        w[5] = self.taubin_lambda.to_bits();
        w[6] = self.taubin_mu.to_bits();
        w[7] = self.smooth_gap_m.to_bits();
        w[8] = self.split_gap_ns;
        w[9] = self.split_geometry;
        w[10] = self.roi_x_min_m.to_bits();
        w[11] = self.roi_x_max_m.to_bits();
        w[12] = self.roi_z_min_m.to_bits();
        w[13] = self.roi_z_max_m.to_bits();
        w[14] = self.output_mode;
        w
    }

    /// The region of interest, if one is set.
    pub fn roi(&self) -> Option<Roi> {
        (self.roi_x_min_m < self.roi_x_max_m).then_some(Roi {
            x_min: self.roi_x_min_m,
            x_max: self.roi_x_max_m,
            z_min: self.roi_z_min_m,
            z_max: self.roi_z_max_m,
        })
    }

    /// What the core sends per line.
    pub fn output_mode(&self) -> OutputMode {
        if self.output_mode == 1 {
            OutputMode::Candidates
        } else {
            OutputMode::Points
        }
    }

    /// Parses and checks a parameter block; the first offending word is reported.
    pub fn from_words(words: &[u32; CONFIG_WORDS]) -> Result<Self, ParamsError> {
        // `lo_open`: whether the lower bound itself is excluded (likewise `hi_open`).
        fn f(
            words: &[u32; CONFIG_WORDS],
            param: Param,
            lo: f32,
            lo_open: bool,
            hi: f32,
            hi_open: bool,
        ) -> Result<f32, ParamsError> {
            let word = words[param.word()];
            let v = f32::from_bits(word);
            // NaN fails every comparison, so it is rejected here too.
            let above = if lo_open { v > lo } else { v >= lo };
            let below = if hi_open { v < hi } else { v <= hi };
            if above && below {
                Ok(v)
            } else {
                Err(ParamsError::OutOfRange { param })
            }
        }
        fn int(words: &[u32; CONFIG_WORDS], param: Param, max: u32) -> Result<u32, ParamsError> {
            let word = words[param.word()];
            if word <= max {
                Ok(word)
            } else {
                Err(ParamsError::OutOfRange { param })
            }
        }
        for (index, &word) in words.iter().enumerate().skip(FIRST_RESERVED) {
            if word != 0 {
                return Err(ParamsError::ReservedNotZero { index: index as u8 });
            }
        }
        let d_b_m = f(words, Param::DBM, 0.0, true, 10.0, false)?;
        let irregular_deg = f(words, Param::IrregularDeg, 0.0, true, 180.0, false)?;
        let tau_min_deg = f(words, Param::TauMinDeg, 0.0, false, 180.0, true)?;
        let tau_max_deg = f(words, Param::TauMaxDeg, tau_min_deg, true, 180.0, false)?;
        let taubin_steps = int(words, Param::TaubinSteps, 200)?;
        let taubin_lambda = f(words, Param::TaubinLambda, 0.0, true, 1.0, false)?;
        let taubin_mu = f(words, Param::TaubinMu, -1.0, false, 0.0, true)?;
        let smooth_gap_m = f(words, Param::SmoothGapM, 0.0, false, 100.0, false)?;
        let split_gap_ns = words[Param::SplitGapNs.word()];
        let split_geometry = int(words, Param::SplitGeometry, 2)?;
        let l = ROI_LIMIT_M;
        let roi_x_min_m = f(words, Param::RoiXMinM, -l, false, l, false)?;
        let roi_z_min_m = f(words, Param::RoiZMinM, -l, false, l, false)?;
        let off = (10..14).all(|i| words[i] == 0);
        let (roi_x_max_m, roi_z_max_m) = if off {
            (0.0, 0.0)
        } else {
            (
                f(words, Param::RoiXMaxM, roi_x_min_m, true, l, false)?,
                f(words, Param::RoiZMaxM, roi_z_min_m, true, l, false)?,
            )
        };
        let output_mode = int(words, Param::OutputMode, 1)?;
        Ok(Self {
            d_b_m,
            irregular_deg,
            tau_min_deg,
            tau_max_deg,
            taubin_steps,
            taubin_lambda,
            taubin_mu,
            smooth_gap_m,
            split_gap_ns,
            split_geometry,
            roi_x_min_m,
            roi_x_max_m,
            roi_z_min_m,
            roi_z_max_m,
            output_mode,
        })
    }

    /// The assembler's part of the parameters.
    pub fn split_params(&self) -> SplitParams {
        SplitParams {
            gap_ns: u64::from(self.split_gap_ns),
            geometry: match self.split_geometry {
                1 => GeometrySplit::Always,
                2 => GeometrySplit::Never,
                _ => GeometrySplit::Auto,
            },
        }
    }

    /// Checks the parameters against the ranges of the config words (the same check as
    /// [`Self::from_words`]).
    pub fn validate(&self) -> Result<(), ParamsError> {
        Self::from_words(&self.to_words()).map(|_| ())
    }

    /// A stable 32-bit hash of the parameter words (echoed in every output packet):
    /// 32-bit FNV-1a over the little-endian bytes of [`Self::to_words`].
    pub fn hash(&self) -> u32 {
        let mut h: u32 = 0x811c_9dc5;
        for w in self.to_words() {
            for b in w.to_le_bytes() {
                h ^= u32::from(b);
                h = h.wrapping_mul(0x0100_0193);
            }
        }
        h
    }
}

impl Default for KernelParams {
    fn default() -> Self {
        Self::DEFAULT
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_round_trip() {
        let p = KernelParams::DEFAULT;
        assert_eq!(p.validate(), Ok(()));
        assert_eq!(KernelParams::from_words(&p.to_words()), Ok(p));
        // The paper's Taubin values (§2.5).
        assert_eq!(p.taubin_steps, 20);
        assert_eq!(p.taubin_lambda, 0.6307);
        assert_eq!(p.taubin_mu, -0.6732);
    }

    #[test]
    fn split_params_match_the_assembler() {
        assert_eq!(KernelParams::DEFAULT.split_params(), SplitParams::DEFAULT);
        let p = KernelParams {
            split_gap_ns: 7,
            split_geometry: 2,
            ..KernelParams::DEFAULT
        };
        assert_eq!(p.split_params().gap_ns, 7);
        assert_eq!(p.split_params().geometry, GeometrySplit::Never);
    }

    #[test]
    fn word_layout_is_fixed() {
        let w = KernelParams::DEFAULT.to_words();
        assert_eq!(w[0], 0.07f32.to_bits());
        assert_eq!(w[0], 0x3d8f_5c29);
        assert_eq!(w[4], 20);
        assert_eq!(w[6], (-0.6732f32).to_bits());
        assert!(w[FIRST_RESERVED..].iter().all(|&x| x == 0));
    }

    #[test]
    fn hash_is_fnv1a_of_the_words() {
        // FNV-1a of 64 zero bytes, computed by hand from the definition: each zero byte
        // leaves the xor unchanged, so h = offset · prime^64 (mod 2^32).
        let mut expect: u32 = 0x811c_9dc5;
        for _ in 0..64 {
            expect = expect.wrapping_mul(0x0100_0193);
        }
        let zero = KernelParams {
            d_b_m: 0.0,
            irregular_deg: 0.0,
            tau_min_deg: 0.0,
            tau_max_deg: 0.0,
            taubin_steps: 0,
            taubin_lambda: 0.0,
            taubin_mu: 0.0,
            smooth_gap_m: 0.0,
            split_gap_ns: 0,
            split_geometry: 0,
            roi_x_min_m: 0.0,
            roi_x_max_m: 0.0,
            roi_z_min_m: 0.0,
            roi_z_max_m: 0.0,
            output_mode: 0,
        };
        assert_eq!(zero.hash(), expect);
        let a = KernelParams::DEFAULT;
        let b = KernelParams {
            d_b_m: 0.11,
            ..KernelParams::DEFAULT
        };
        assert_ne!(a.hash(), b.hash());
        assert_eq!(a.hash(), KernelParams::DEFAULT.hash());
    }

    #[test]
    fn bad_words_are_rejected_naming_their_parameter() {
        let good = KernelParams::DEFAULT.to_words();
        let cases: [(Param, u32); 14] = [
            (Param::DBM, f32::NAN.to_bits()),
            (Param::DBM, 0.0f32.to_bits()),
            (Param::DBM, (-0.1f32).to_bits()),
            (Param::IrregularDeg, f32::INFINITY.to_bits()),
            (Param::IrregularDeg, 181.0f32.to_bits()),
            (Param::TauMinDeg, (-1.0f32).to_bits()),
            (Param::TauMaxDeg, 25.0f32.to_bits()), // below τ_min = 30
            (Param::TaubinSteps, 201),
            (Param::TaubinLambda, 1.5f32.to_bits()),
            (Param::TaubinMu, 0.5f32.to_bits()),
            (Param::SmoothGapM, f32::NEG_INFINITY.to_bits()),
            (Param::SplitGeometry, 3),
            (Param::RoiXMinM, 2001.0f32.to_bits()),
            (Param::OutputMode, 2),
        ];
        for (param, word) in cases {
            let mut w = good;
            w[param.word()] = word;
            assert_eq!(
                KernelParams::from_words(&w),
                Err(ParamsError::OutOfRange { param }),
                "{param:?}"
            );
        }
        let mut w = good;
        w[15] = 1;
        assert_eq!(
            KernelParams::from_words(&w),
            Err(ParamsError::ReservedNotZero { index: 15 })
        );
        // A region must have positive extents; one bound alone is not a region.
        let mut w = good;
        w[Param::RoiXMaxM.word()] = 1.0f32.to_bits();
        assert_eq!(
            KernelParams::from_words(&w),
            Err(ParamsError::OutOfRange {
                param: Param::RoiZMaxM
            })
        );
        w[Param::RoiXMinM.word()] = 1.0f32.to_bits();
        assert_eq!(
            KernelParams::from_words(&w),
            Err(ParamsError::OutOfRange {
                param: Param::RoiXMaxM
            })
        );
    }

    /// The region of interest: off when its four words are zero, else a box with positive
    /// extents within ±2000 m; the words round-trip.
    #[test]
    fn region_of_interest_words() {
        assert_eq!(KernelParams::DEFAULT.roi(), None);
        let p = KernelParams {
            roi_x_min_m: -15.0,
            roi_x_max_m: 15.0,
            roi_z_min_m: -4.0,
            roi_z_max_m: -1.0,
            output_mode: 1,
            ..KernelParams::DEFAULT
        };
        assert_eq!(KernelParams::from_words(&p.to_words()), Ok(p));
        let roi = p.roi().unwrap();
        assert!(roi.contains(15.0, -1.0) && roi.contains(-15.0, -4.0));
        assert!(!roi.contains(15.01, -2.0) && !roi.contains(0.0, -0.99));
        assert!(!roi.contains(f32::NAN, -2.0));
        assert_eq!(p.output_mode(), OutputMode::Candidates);
        for (param, v) in [
            (Param::RoiXMinM, -2000.5f32),
            (Param::RoiXMaxM, 2000.5),
            (Param::RoiXMaxM, -15.0),
            (Param::RoiZMinM, f32::NAN),
            (Param::RoiZMaxM, -4.0),
        ] {
            let mut w = p.to_words();
            w[param.word()] = v.to_bits();
            assert_eq!(
                KernelParams::from_words(&w),
                Err(ParamsError::OutOfRange { param }),
                "{param:?} = {v}"
            );
        }
    }

    /// The messages a user reads: the field's name and its range.
    #[test]
    fn error_messages_name_the_field_and_range() {
        extern crate std;
        use std::string::ToString;
        let msg = |p: KernelParams| p.validate().unwrap_err().to_string();
        assert_eq!(
            msg(KernelParams {
                tau_max_deg: 30.0,
                ..KernelParams::DEFAULT
            }),
            "tau_max_deg is NaN, infinite or outside its range (tau_min_deg, 180]"
        );
        assert_eq!(
            msg(KernelParams {
                d_b_m: f32::NAN,
                ..KernelParams::DEFAULT
            }),
            "d_b_m is NaN, infinite or outside its range (0, 10]"
        );
        assert_eq!(
            msg(KernelParams {
                taubin_mu: -1.5,
                ..KernelParams::DEFAULT
            }),
            "taubin_mu is NaN, infinite or outside its range [-1, 0)"
        );
        assert_eq!(
            msg(KernelParams {
                taubin_steps: 500,
                ..KernelParams::DEFAULT
            }),
            "taubin_steps is outside its range 0..=200"
        );
        assert_eq!(
            msg(KernelParams {
                split_geometry: 3,
                ..KernelParams::DEFAULT
            }),
            "split_geometry is outside its range 0..=2 (0 = auto, 1 = always, 2 = never)"
        );
        let mut w = KernelParams::DEFAULT.to_words();
        w[15] = 0xff;
        assert_eq!(
            KernelParams::from_words(&w).unwrap_err().to_string(),
            "config word 15 is reserved and must be 0"
        );
    }

    /// [`Param::range`] is what `from_words` enforces: for every f32 parameter, the bounds
    /// read from the range text are accepted or rejected as its brackets say, and the next
    /// float outside each bound is rejected; integer ranges likewise at `max` and `max + 1`.
    #[test]
    fn range_texts_match_the_checks() {
        extern crate std;
        let base = KernelParams {
            tau_min_deg: 10.0,
            tau_max_deg: 180.0,
            ..KernelParams::DEFAULT
        }
        .to_words();
        let next_up = |v: f32| {
            if v == 0.0 {
                f32::from_bits(1)
            } else if v > 0.0 {
                f32::from_bits(v.to_bits() + 1)
            } else {
                f32::from_bits(v.to_bits() - 1)
            }
        };
        let next_down = |v: f32| -next_up(-v);
        let accepts = |param: Param, word: u32| {
            let mut w = base;
            w[param.word()] = word;
            match KernelParams::from_words(&w) {
                Ok(_) => true,
                Err(e) => {
                    assert_eq!(e, ParamsError::OutOfRange { param });
                    false
                }
            }
        };
        for param in Param::ALL {
            assert_eq!(
                param.word(),
                Param::ALL.iter().position(|&p| p == param).unwrap()
            );
            let text = param.range();
            // The region's bounds depend on each other: `region_of_interest_words` checks
            // them.
            if matches!(
                param,
                Param::RoiXMinM | Param::RoiXMaxM | Param::RoiZMinM | Param::RoiZMaxM
            ) {
                continue;
            }
            if param.is_f32() {
                let (lo_open, hi_open) = (text.starts_with('('), text.ends_with(')'));
                let inner = &text[1..text.len() - 1];
                let (lo, hi) = inner.split_once(", ").unwrap();
                let lo: f32 = if lo == "tau_min_deg" {
                    10.0
                } else {
                    lo.parse().unwrap()
                };
                let hi: f32 = hi.parse().unwrap();
                assert_eq!(accepts(param, lo.to_bits()), !lo_open, "{text}");
                assert_eq!(accepts(param, hi.to_bits()), !hi_open, "{text}");
                assert!(accepts(param, next_up(lo).to_bits()), "{text}");
                assert!(accepts(param, next_down(hi).to_bits()), "{text}");
                assert!(!accepts(param, next_down(lo).to_bits()), "{text}");
                assert!(!accepts(param, next_up(hi).to_bits()), "{text}");
                assert!(!accepts(param, f32::NAN.to_bits()), "{text}");
            } else if text == "any u32" {
                assert!(accepts(param, 0) && accepts(param, u32::MAX));
            } else {
                let ints = text.split(' ').next().unwrap();
                let (lo, hi) = ints.split_once("..=").unwrap();
                let (lo, hi): (u32, u32) = (lo.parse().unwrap(), hi.parse().unwrap());
                assert_eq!(lo, 0);
                assert!(accepts(param, hi), "{text}");
                assert!(!accepts(param, hi + 1), "{text}");
            }
        }
    }
}
