//! The parameters of the Qiu et al. (2016) method, one struct, fixed across scenes as the
//! paper insists (§4.2: "we use the same parameters through the experiments").
//!
//! The paper gives only the section size (§3.1, 200 m × 50 m), α = 0.5 m and
//! β = 0.01 … 0.08 m (§4.2). Every other value is ours; its doc comment says how it was
//! chosen. A TOML `[qiu]` table deserialises into this struct; missing keys take the
//! defaults (`#[serde(default)]`).

use serde::{Deserialize, Serialize};

/// Parameters of `qiu::extract_edges`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct QiuParams {
    // --- §3.1 partition --------------------------------------------------------------
    /// Section length along the trajectory, metres. Paper §3.1: 200 m.
    pub section_length_m: f64,
    /// Section width across the trajectory (points farther than half of it from the
    /// trajectory pose at their GPS time are left out), metres. Paper §3.1: 50 m.
    pub section_width_m: f64,
    /// Overlap of consecutive sections, metres. Not in the paper (its Fig. 3 shows overlap
    /// without a number): 20 m, so that each section's kept middle part (half an overlap
    /// in from either end) is farther from the section's end than the scanner sees ahead
    /// or behind (a few metres for a scan plane yawed 45°).
    pub section_overlap_m: f64,
    /// A time gap between consecutive trajectory samples longer than this starts a new run
    /// of sections (§3.1 names "the time difference between the consecutive points" as a
    /// manual parameter without a value), seconds. 2 s: well above any trajectory sampling
    /// interval (10–200 Hz), well below a stop-and-go pause between two passes.
    pub max_time_gap_s: f64,

    // --- §3.2 pre-processing ---------------------------------------------------------
    /// Voxel edge of the down-sampling grid, metres. Not in the paper: 50 mm keeps three
    /// voxels on the face of an 80 mm curb while evening out the 10× density contrast
    /// between the road under the scanner and the far sidewalk.
    pub voxel_m: f64,
    /// Neighbours per point for statistical outlier removal (Rusu et al. 2008). Not in the
    /// paper; 8 is enough for a stable mean distance on a voxelised surface.
    pub sor_k: usize,
    /// A point is an outlier when its mean neighbour distance exceeds μ + `sor_std_mul`·σ
    /// of all points' mean distances. Not in the paper; 2.0 removes isolated returns and
    /// keeps the thin rows of points on curb faces.
    pub sor_std_mul: f64,
    /// Run the outlier removal after the voxel grid (default) instead of before it as the
    /// paper lists them. On an evened density the μ + kσ statistic is about the surface,
    /// not about the range to the scanner, and it is 3–5× cheaper; isolated returns are
    /// still isolated after down-sampling. `false` gives the paper's order.
    pub sor_after_voxel: bool,

    // --- §3.3.1 terrain normalisation --------------------------------------------------
    /// Cell of the minimum-z grid, metres. Not in the paper: 0.5 m, small enough that a
    /// 2 % cross slope adds at most 10 mm inside a cell (below the smallest β that
    /// survives range noise), large enough that most cells hold road points.
    pub grid_cell_m: f64,

    // --- §3.3.2 rough segmentation -------------------------------------------------------
    /// Rough-plane RANSAC threshold α, metres. Paper §4.2: 0.5 m.
    pub alpha_m: f64,
    /// Refined-plane RANSAC thresholds β_i, metres. Paper §4.2: 0.01 … 0.08 m.
    pub betas_m: Vec<f64>,
    /// RANSAC iterations per plane. Not in the paper: with at least half the points on the
    /// plane, 100 draws of 3 points miss it with probability 0.875^100 ≈ 1.6e-6.
    pub ransac_iterations: usize,
    /// Largest tilt of a RANSAC plane from horizontal, degrees. Not in the paper: a guard
    /// so that a wall can never be taken for the road (after normalisation the road is
    /// level, so 20° never rejects it).
    pub ransac_max_tilt_deg: f64,
    /// Seed of the RANSAC random draws (mixed with the section index), so results are
    /// reproducible and independent of the thread count.
    pub seed: u64,
    /// "We search inliers near an outlier": an outlier of a refined plane is a candidate
    /// edge point when a refined-plane inlier lies within this 3D distance, metres. Not in
    /// the paper: 0.1 m, two voxels, so only the lower curb face next to the road
    /// qualifies, not the curb top.
    pub neighbour_radius_m: f64,
    /// The inlier next to a candidate must lie at least `min_rise_beta`·β lower before
    /// normalisation (see `segment::candidate_edge_points`): an edge stands above the
    /// pavement beside it. Not in the paper (0 gives its plain rule); 1.0 asks of the
    /// un-normalised heights what the refined plane asks of the normalised ones.
    pub min_rise_beta: f64,
    /// A candidate set (one per β) with fewer points than this on both sides together is
    /// not considered when choosing by E_s (a near-empty set would have a meaningless
    /// variance). Not in the paper.
    pub min_candidates: usize,
    /// Among candidate sets whose E_s is within this share of the smallest, the smallest β
    /// wins. The paper takes the smallest E_s (0, the default); a tolerance was tried on
    /// `sapporo` and let road noise (β = 0.01 m) win, so it stays off.
    pub energy_tolerance: f64,
    /// Also within reach of the smallest E_s: sets whose √E_s (a spread in metres) is at
    /// most this much above the smallest √E_s; of those the smallest β wins. Not in the
    /// paper. A clean edge line's spread is a few millimetres (2–9 mm measured on
    /// `sapporo`); road noise (β below the range noise) gives 17 mm on a uniformly dense
    /// synthetic road and 0.1 m on simulated scans; so 0.01 m treats every clean line as
    /// equally smooth and lets the smallest β — the one that still sees a low curb — win,
    /// instead of a coin toss between spreads of 2 and 3 mm that on `sapporo` picked
    /// β = 0.07 m against an 80 mm curb.
    pub energy_slack_m: f64,
    /// Per side, starting from the smallest β: a candidate set with more than this many
    /// times the candidates of the next larger β's set lies within the range noise and is
    /// not considered, nor is any smaller β's. Not in the paper. Below the noise, outliers
    /// of the refined plane fill the whole road and their count grows several-fold per
    /// step of β; an edge's candidates thin out slowly with β. Their innermost points then
    /// trace the inner border of the returns (the strip the vehicle's body hides), a
    /// smooth line that E_s alone would choose. Measured on random tuning streets: noise
    /// steps 1.8–5.6, clean steps 1.0–1.35.
    pub noise_count_ratio: f64,
    /// Per side, candidates of the smaller βs (those not within the noise, see
    /// `noise_count_ratio`) are added to the chosen β's set where their offset from the
    /// trajectory is within this of the chosen set's innermost line (the median of its
    /// innermost offsets within `low_beta_window_m` along the trajectory), metres; 0 turns
    /// it off. Not in the paper, which keeps one β per section: the β that sees a 150 mm
    /// curb without the road's noise (0.03–0.05 m on noisy scans) leaves a curb cut's
    /// 15–40 mm lip below the refined plane's reach, and the cut a gap. 0.3 m: the width
    /// step's tolerance.
    pub low_beta_corridor_m: f64,
    /// Along-track window of the innermost line that [`Self::low_beta_corridor_m`] follows,
    /// metres: 20 m spans the longest curb cut (12 m and its transitions) with curb on
    /// either side.
    pub low_beta_window_m: f64,
    /// Candidates on lines running across the trajectory (a side street's curb beyond a
    /// corner) are fitted as lines of their own, ordered by offset (see
    /// `refine::split_across`). Not in the paper, whose continuity step follows the
    /// trajectory; `false` gives that.
    pub split_across: bool,
    /// A road edge has ground on both sides: a chain whose median height step across it
    /// cannot be measured (fewer than 3 points within `height_band_m` on one side, as at
    /// the foot of a wall) or is below this is dropped before the longest chains are
    /// chosen, metres. Not in the paper (its scenes are judged by eye); 0.02 m keeps curb
    /// cuts (20–30 mm) that were joined into a curb chain.
    pub min_step_m: f64,
    /// A chain whose median height step is above this is an obstacle's foot — a parked
    /// car's side, a wall, a fence — not a road edge, and is dropped like one below
    /// `min_step_m`, metres. Not in the paper (its parked cars are left to the width step,
    /// §4.3 Urban 3). 0.5 m: above any curb (100–250 mm, 300 mm at most), below a car
    /// body's side seen across its foot (0.5–1.5 m).
    pub max_step_m: f64,

    // --- §3.4.1 refinement by road width -------------------------------------------------
    /// Eq. 3: R_i must lie within this distance of the line L_i P_i, metres. Not in the
    /// paper: 0.25 m, about half the along-track spacing of candidates after voxelising.
    pub width_pair_m: f64,
    /// Histogram bin of the temporary road widths, metres. Not in the paper.
    pub width_bin_m: f64,
    /// Widths (and per-side offsets) within this of the most frequent one count as the
    /// road width, metres. Not in the paper: 0.3 m.
    pub width_tolerance_m: f64,
    /// Along-track window in which the most frequent width is taken, metres. The paper takes
    /// one width per section; a window follows a width change inside a 200 m section
    /// (e.g. 7.5 m → 11.5 m).
    pub width_window_m: f64,
    /// A point without a matching partner (its partner hidden, e.g. by a parked car) is
    /// kept when its offset from the trajectory is within `width_tolerance_m` of the local
    /// trend (the line through the median points of the window's two halves) of the offsets
    /// of the matched points of its side within this along-track window, metres.
    /// Not in the paper (which loses such points, cf. its Urban 3): 10 m, short enough to
    /// follow the vehicle swerving around a parked car.
    pub offset_window_m: f64,

    // --- §3.4.2 refinement by continuity ---------------------------------------------------
    /// Euclidean cluster tolerance, metres. Not in the paper: 0.6 m bridges the
    /// along-track spacing of candidates on a far curb.
    pub cluster_tolerance_m: f64,
    /// Clusters with fewer points are dropped. Not in the paper.
    pub min_cluster_points: usize,
    /// A Euclidean cluster of candidates of which at least this share was kept by the
    /// road-width step is kept whole (see `refine::refine_by_continuity`). Not in the paper,
    /// which applies the width step point by point and so cuts every intersection's arc off
    /// where its offset leaves the road's width; 0.5: a majority. Above 1, the paper's
    /// point-by-point rule.
    pub cluster_keep_share: f64,
    /// A Euclidean cluster whose offsets from the trajectory span at least this, metres,
    /// is kept whole too, however little of it the road-width step kept: a corner's arc
    /// leaves the road's width by design, and where no straight curb joins it (the drive
    /// starts or ends at the corner, or the curb before it is a cut or hidden) the share
    /// rule loses it. The height step still judges the line (road noise is flat, a car's
    /// end or a wall too high). Not in the paper; 0 turns it off. 1.5 m: five times the
    /// width step's tolerance, more than a swerve around a parked car moves a curb's
    /// offset within one cluster.
    pub cluster_keep_spread_m: f64,
    /// Such a cluster is kept whole only when its line turns away from the road at its
    /// outer end by at least this angle to the heading, degrees (see
    /// `refine::refine_by_continuity`): a corner's arc does, up to the 45° where
    /// `split_across` takes its rest; a curb whose offset changes with a road-width change
    /// (at most 9° on random streets) or a lane change (at most 26°: 7.6 m over 25 m) does
    /// not. Not in the paper. 30°, between the two; 0 keeps every thin spread cluster.
    pub cluster_keep_turn_deg: f64,
    /// Points of a cluster are summarised every this many metres along its main direction
    /// before fitting line segments. Not in the paper.
    pub bin_m: f64,
    /// Douglas–Peucker tolerance of the fitted line segments, metres. Not in the paper.
    pub segment_tolerance_m: f64,
    /// Line segments are joined when the gap between them is at most this, metres. Not in
    /// the paper: 5 m bridges a curb cut or a short occlusion.
    pub join_gap_m: f64,
    /// γ of Eq. 4: largest change of direction between joined segments, degrees. Not in
    /// the paper.
    pub join_angle_deg: f64,
    /// Largest sideways offset of the next segment's start from the current segment's line
    /// when joining, metres. Not in the paper.
    pub join_lateral_m: f64,
    /// Two chains of one side that line up (the joins' γ and `join_lateral_m`) across a gap
    /// longer than `join_gap_m` and at most this are joined when the ground across the
    /// straight line between them steps up outward by `min_step_m` to `max_step_m` over
    /// most of it (see `refine::bridge_gaps`), metres; 0 turns it off. Not in the paper. A
    /// curb cut without a lip (a ramp rising from the toe) has no candidates, as no
    /// pavement point beside the ramp's foot lies a β lower; its toe is still an edge.
    /// 13 m: the longest cut (12 m) and a little; an intersection's mouth, as wide or
    /// wider, is flat across and fails the step.
    pub bridge_gap_m: f64,
    /// Chains shorter than this are dropped ("the longest … is considered to be the best
    /// road edge"), metres. Not in the paper.
    pub min_chain_m: f64,
    /// A chain overlapping a longer kept chain on the same side over more than this share of
    /// its along-track extent is dropped (only the longest of parallel chains is kept).
    pub max_chain_overlap: f64,

    // --- output ---------------------------------------------------------------------------
    /// The height step across a line is measured between points from `height_band_m[0]` to
    /// `height_band_m[1]` metres on either side of it. Not in the paper.
    pub height_band_m: [f64; 2],
}

impl Default for QiuParams {
    fn default() -> Self {
        Self {
            section_length_m: 200.0,
            section_width_m: 50.0,
            section_overlap_m: 20.0,
            max_time_gap_s: 2.0,
            voxel_m: 0.05,
            sor_k: 8,
            sor_std_mul: 2.0,
            sor_after_voxel: true,
            grid_cell_m: 0.5,
            alpha_m: 0.5,
            betas_m: vec![0.01, 0.02, 0.03, 0.04, 0.05, 0.06, 0.07, 0.08],
            ransac_iterations: 100,
            ransac_max_tilt_deg: 20.0,
            seed: 2016,
            neighbour_radius_m: 0.1,
            min_rise_beta: 1.0,
            min_candidates: 30,
            energy_tolerance: 0.0,
            energy_slack_m: 0.01,
            noise_count_ratio: 1.5,
            low_beta_corridor_m: 0.3,
            low_beta_window_m: 20.0,
            split_across: true,
            min_step_m: 0.02,
            max_step_m: 0.5,
            width_pair_m: 0.25,
            width_bin_m: 0.1,
            width_tolerance_m: 0.3,
            width_window_m: 50.0,
            offset_window_m: 10.0,
            cluster_tolerance_m: 0.6,
            min_cluster_points: 5,
            cluster_keep_share: 0.5,
            cluster_keep_spread_m: 1.5,
            cluster_keep_turn_deg: 30.0,
            bin_m: 0.5,
            segment_tolerance_m: 0.1,
            join_gap_m: 5.0,
            join_angle_deg: 15.0,
            join_lateral_m: 0.3,
            bridge_gap_m: 13.0,
            min_chain_m: 3.0,
            max_chain_overlap: 0.5,
            height_band_m: [0.15, 0.6],
        }
    }
}

/// Why a parameter set was refused.
#[derive(Debug, thiserror::Error, PartialEq)]
#[error("qiu parameters: {0}")]
pub struct QiuParamsError(pub String);

impl QiuParams {
    /// Checks that every value is usable (positive lengths, at least one β, …).
    pub fn validate(&self) -> Result<(), QiuParamsError> {
        let pos = [
            ("section_length_m", self.section_length_m),
            ("section_width_m", self.section_width_m),
            ("max_time_gap_s", self.max_time_gap_s),
            ("voxel_m", self.voxel_m),
            ("sor_std_mul", self.sor_std_mul),
            ("grid_cell_m", self.grid_cell_m),
            ("alpha_m", self.alpha_m),
            ("noise_count_ratio", self.noise_count_ratio),
            ("neighbour_radius_m", self.neighbour_radius_m),
            ("width_pair_m", self.width_pair_m),
            ("width_bin_m", self.width_bin_m),
            ("width_tolerance_m", self.width_tolerance_m),
            ("width_window_m", self.width_window_m),
            ("offset_window_m", self.offset_window_m),
            ("cluster_tolerance_m", self.cluster_tolerance_m),
            ("bin_m", self.bin_m),
            ("segment_tolerance_m", self.segment_tolerance_m),
            ("cluster_keep_share", self.cluster_keep_share),
            ("join_angle_deg", self.join_angle_deg),
            ("join_lateral_m", self.join_lateral_m),
        ];
        for (name, v) in pos {
            if !(v.is_finite() && v > 0.0) {
                return Err(QiuParamsError(format!(
                    "{name} must be a positive number, found {v}"
                )));
            }
        }
        let nonneg = [
            ("join_gap_m", self.join_gap_m),
            ("min_chain_m", self.min_chain_m),
            ("ransac_max_tilt_deg", self.ransac_max_tilt_deg),
            ("energy_tolerance", self.energy_tolerance),
            ("energy_slack_m", self.energy_slack_m),
            ("min_step_m", self.min_step_m),
            ("max_step_m", self.max_step_m),
            ("min_rise_beta", self.min_rise_beta),
            ("low_beta_corridor_m", self.low_beta_corridor_m),
            ("low_beta_window_m", self.low_beta_window_m),
            ("cluster_keep_spread_m", self.cluster_keep_spread_m),
            ("cluster_keep_turn_deg", self.cluster_keep_turn_deg),
            ("bridge_gap_m", self.bridge_gap_m),
        ];
        for (name, v) in nonneg {
            if !(v.is_finite() && v >= 0.0) {
                return Err(QiuParamsError(format!(
                    "{name} must be zero or more, found {v}"
                )));
            }
        }
        if self.cluster_keep_turn_deg > 90.0 {
            return Err(QiuParamsError(format!(
                "cluster_keep_turn_deg must be at most 90, found {}",
                self.cluster_keep_turn_deg
            )));
        }
        if self.max_step_m < self.min_step_m {
            return Err(QiuParamsError(format!(
                "max_step_m must be at least min_step_m ({}), found {}",
                self.min_step_m, self.max_step_m
            )));
        }
        if !(self.section_overlap_m >= 0.0 && self.section_overlap_m < self.section_length_m) {
            return Err(QiuParamsError(format!(
                "section_overlap_m must be in [0, section_length_m), found {}",
                self.section_overlap_m
            )));
        }
        if self.betas_m.is_empty() || self.betas_m.iter().any(|b| !(b.is_finite() && *b > 0.0)) {
            return Err(QiuParamsError(
                "betas_m must hold at least one positive value".into(),
            ));
        }
        if self.sor_k == 0 || self.ransac_iterations == 0 {
            return Err(QiuParamsError(
                "sor_k and ransac_iterations must be at least 1".into(),
            ));
        }
        if !(0.0..=1.0).contains(&self.max_chain_overlap) {
            return Err(QiuParamsError("max_chain_overlap must be in [0, 1]".into()));
        }
        let [a, b] = self.height_band_m;
        if !(a.is_finite() && b.is_finite() && 0.0 <= a && a < b) {
            return Err(QiuParamsError(format!(
                "height_band_m must be [inner, outer] with 0 <= inner < outer, found [{a}, {b}]"
            )));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_carry_the_papers_values_and_validate() {
        let p = QiuParams::default();
        assert_eq!(p.section_length_m, 200.0);
        assert_eq!(p.section_width_m, 50.0);
        assert_eq!(p.alpha_m, 0.5);
        assert_eq!(p.betas_m.len(), 8);
        assert!((p.betas_m[0] - 0.01).abs() < 1e-12 && (p.betas_m[7] - 0.08).abs() < 1e-12);
        p.validate().unwrap();
    }

    #[test]
    fn a_partial_toml_table_keeps_the_other_defaults() {
        let p: QiuParams = toml::from_str("alpha_m = 0.4\nsection_length_m = 100.0\n").unwrap();
        assert_eq!(p.alpha_m, 0.4);
        assert_eq!(p.section_length_m, 100.0);
        assert_eq!(p.section_width_m, 50.0);
        let back: QiuParams = toml::from_str(&toml::to_string(&p).unwrap()).unwrap();
        assert_eq!(back, p);
    }

    #[test]
    fn bad_values_are_refused_with_the_name() {
        let p = QiuParams {
            section_overlap_m: 300.0,
            ..QiuParams::default()
        };
        assert!(p
            .validate()
            .unwrap_err()
            .to_string()
            .contains("section_overlap_m"));
        let p = QiuParams {
            betas_m: vec![],
            ..QiuParams::default()
        };
        assert!(p.validate().unwrap_err().to_string().contains("betas_m"));
        let p = QiuParams {
            voxel_m: f64::NAN,
            ..QiuParams::default()
        };
        assert!(p.validate().unwrap_err().to_string().contains("voxel_m"));
    }
}
