//! [`BendParams`]: every parameter of the host half of the bend method (Honma et al.
//! §2.6–2.7), with defaults. The paper names the parameters but gives no values for any of
//! them; each field says how its default was chosen.

use serde::{Deserialize, Serialize};

/// Parameters of seeding (§2.6), tracking (§2.7, Eq. 4–8) and the post-filters.
///
/// Serialised as a TOML table; every field may be left out (`#[serde(default)]`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BendParams {
    // ---- Seeding (§2.6) ----
    /// L_s: length of the intervals along the trajectory that the seed candidates of one
    /// side are cut into, metres. Not given in the paper; 2 m holds about 18 scanlines at
    /// 40 km/h (enough for RANSAC) and is short enough that a curb between two driveways
    /// still gets its own interval.
    pub seed_interval_m: f64,
    /// RANSAC iterations per interval. Not in the paper; with 50 % outliers, 64 pairs miss an
    /// all-inlier pair with probability 0.75^64 ≈ 1e-8. Fewer pairs than this are all tried.
    pub ransac_iterations: u32,
    /// RANSAC inlier distance, metres. Not in the paper; candidates on one curb toe scatter
    /// by the kernel's 1–3 cm point spacing, so 40 mm keeps them and rejects cars and weeds.
    pub ransac_inlier_m: f64,
    /// Fewest inliers for an interval to give a seed. Not in the paper; a line through fewer
    /// than 5 candidates is too easily a coincidence.
    pub ransac_min_inliers: u32,
    /// Smallest inlier share for an interval to give a seed. Not in the paper; below one half
    /// the candidates are mostly not one curb (an intersection or a car), and a seed taken
    /// there starts a track on the wrong thing.
    pub ransac_min_inlier_ratio: f64,
    /// Seed of the RANSAC random generator (ChaCha8), mixed with the side and interval
    /// number so that every interval draws the same pairs on every run.
    pub ransac_seed: u64,

    // ---- Tracking (§2.7) ----
    /// Search distance: how far ahead of the current edge point the search position lies,
    /// metres (Fig. 7). Not in the paper; a little more than the 0.11 m scanline spacing at
    /// 40 km/h so that the search set always reaches the next scanline.
    pub search_distance_m: f64,
    /// Radius of the local point set S around the search position, horizontal, metres.
    /// Not in the paper; 0.1 m covers the next one or two scanlines at 20–60 km/h while
    /// staying narrower than a curb top (so S is not dominated by the sidewalk).
    pub search_radius_m: f64,
    /// Half-height of S around the predicted height, metres. Not in the paper (its S is
    /// horizontal); keeps overhanging branches and car bodies out of S. 0.3 m is above any
    /// curb step.
    pub search_half_height_m: f64,
    /// α, weight of E_b (Eq. 4–5). Not in the paper; 1 (E_b is already normalised by σ_ρ).
    pub alpha: f64,
    /// β, weight of E_h (Eq. 4, 6). Not in the paper; chosen so that a point 30° off the
    /// search direction needs about half a standard deviation more ρ to win.
    pub beta: f64,
    /// γ, weight of E_v (Eq. 4, 7). Not in the paper; as β.
    pub gamma: f64,
    /// a, weight of the last difference vector in Eq. 8. Not in the paper; a + b = 1, with
    /// the older vector weighted lower so the direction follows curves with a short lag.
    pub a: f64,
    /// b, weight of the difference vector before it in Eq. 8. Not in the paper; see `a`.
    pub b: f64,
    /// Bend-angle threshold of the stop rule (§2.7): tracking stops when S holds no point
    /// with ρ at least this, degrees. Not in the paper; flat road after the kernel's Taubin
    /// smoothing stays within a few degrees, a 20–30 mm curb cut gives 10–30°.
    pub stop_rho_deg: f64,
    /// Smallest σ_ρ used in E_b (Eq. 5), degrees, so that a set S of near-equal ρ does not
    /// divide by zero. Not in the paper; 1° is below the ρ noise.
    pub min_sigma_rho_deg: f64,
    /// Steps the tracker may take across a search set without a point above
    /// `stop_rho_deg` (extrapolating along the search direction, turning at the running
    /// turn rate) before it stops. 0 is the paper's rule. Not in the paper; 6 steps (0.9 m)
    /// bridge the weak toes of curb cuts and the stretches of intersection corners that run
    /// along a scanline; the effect on the named scenes is in docs/benchmarks.md.
    pub max_gap_steps: u32,
    /// Whether a step whose search set S holds no point with ρ at or above `stop_rho_deg`
    /// looks for the toe on a virtual profile across the search direction, built from the
    /// points of several scanlines (`profile::Profile::toe`), before it counts as a gap. Not
    /// in the paper: its ρ is taken along each scanline, so it flattens where a curb turns to
    /// run along the scanlines (intersection corners and side streets), while the height
    /// step is still there between the scanlines.
    pub profile_fallback: bool,
    /// Half-width of the virtual profile across the search direction, metres: the toe may
    /// lie up to this less 0.15 m from the search position. Not in the paper; 0.45 m leaves
    /// 0.3 m either side, enough for a 5 m corner radius to bend away from a straight
    /// prediction over a few steps.
    pub profile_half_width_m: f64,
    /// Half-length of the virtual profile along the search direction, metres. Not in the
    /// paper; 0.15 m takes in two or three scanlines at 30–40 km/h where a side street's
    /// curb lies between them.
    pub profile_half_length_m: f64,
    /// Smallest height step a virtual profile takes as a curb, metres. Not in the paper;
    /// the same 50 mm that separates curbs from curb cuts (`curb_cut_max_step_m`): only
    /// full curbs are followed between scanlines, never a slight ramp or rut.
    pub profile_min_step_m: f64,
    /// Steepest slope across the profile of the road part and of the curb part of a
    /// virtual profile, so that a ramp (behind a curb cut) is not taken for a step. Not in
    /// the paper; 10 % is above road cross slopes and sidewalk falls.
    pub profile_max_slope: f64,
    /// Steepest fall of a virtual profile's road part towards the toe (the road lower
    /// beside the toe than away from it). Not in the paper: a gutter channel falls to the
    /// toe more steeply than the road, and across a side street's curb the main road's
    /// grade adds to that fall; 15 % takes an 8 % gutter on a 6 % grade. A road part rising
    /// to the toe keeps `profile_max_slope`.
    pub profile_max_road_fall: f64,
    /// How far from the trajectory, metres, each interval's sides are searched for a curb
    /// toe on virtual profiles across the driving direction, which seed tracks besides the
    /// core's candidates (`seed::profile_seeds`; 0 = never). Not in the paper: where a scanline
    /// meets a curb at a grazing angle in plan (a yawed mount, far from the scanner) it
    /// climbs the face over a metre or more and its bend angle never peaks, while the step
    /// is there between the scanlines. 15 m reaches the far curb of a 14 m road from the
    /// near lane.
    pub profile_seed_reach_m: f64,
    /// Whether a track whose ordinary profiles see no toe tries the far leg's longer
    /// profile (`leg::leg_toe`). Not a `[bend]` setting: on profilers it is on; on a ring
    /// file `stream` sets it from `[rings] track_leg_toes`.
    #[serde(skip)]
    pub leg_toes: bool,
    /// Where a spinning sensor's rings see the road past the two ends of the points, for
    /// the seeds of [`super::seed::end_seeds`]; `None` (the default, and on profilers)
    /// seeks none. Not a `[bend]` setting: `stream` sets it from `[rings]` on a ring file.
    #[serde(skip)]
    pub end_view: Option<EndView>,
    /// Longest stretch, metres, a track follows a curb cut's toe on virtual profiles
    /// (`profile::Profile::cut_toe`: the break of slope where the lip is under
    /// `profile_min_step_m`, down to none) after the bend angle and the step have both
    /// faded (0 = never). Not in the paper: a cut's toe has no bend angle worth the name
    /// and no step, yet it continues the curb's line; where no track waits on the cut's
    /// far side to bridge to (the end of the drive, a cut beside a side street) it was
    /// lost. 15 m is a 12 m cut with both transitions.
    pub cut_follow_max_m: f64,
    /// Bend angle, degrees, under which a picked toe is *weak*: road noise reaches it.
    /// Not in the paper; the kernel's τ_min (30°), under which it gives no seed candidate.
    /// A weak pick counts as the curb only where a virtual profile confirms it
    /// (`profile::Profile::toe` or `profile::Profile::cut_toe` beside it).
    pub weak_rho_deg: f64,
    /// Longest stretch, metres, a track goes on unconfirmed weak picks and gap steps
    /// before it stops and drops that stretch (0 = no limit). Not in the paper: on a flat
    /// road the bend angle's noise reaches 10–25° wherever the lines are sparse or noisy,
    /// and above the stop threshold a track walks on it from one parked car to the next and
    /// across the road. 1.5 m is the 0.9 m of gap steps and a little more.
    pub weak_run_max_m: f64,
    /// Upper bound of steps per track (per direction): a safety net only.
    pub max_steps: u32,
    /// Distance, metres, within which a track is taken to have reached another track (it
    /// stops there and the two are joined when they meet end to end). Not in the paper;
    /// half the search radius.
    pub join_distance_m: f64,

    // ---- Bridges (bridge.rs) ----
    /// Longest stretch between two tracks of one side that continue each other and are
    /// joined by the arc through their ends, metres (0 = no bridges). Not in the paper; curb
    /// cuts run 3–12 m and hide their toe from the bend angle when their lip is low, a
    /// parked car hides 4–6 m of curb; side streets open 12 m and more between their
    /// corners' tangent points.
    pub bridge_max_m: f64,
    /// Largest angle between the chord of a bridge and the tangent at either end, degrees.
    /// Not in the paper; a 12 m bridge on a 30 m radius turns by 11° at each end.
    pub bridge_max_turn_deg: f64,
    /// Lateral offset over the bridge that the two tangents may disagree by, metres. Not in
    /// the paper; a car's flank or a bus bay's edge lies 0.2 m or more beside the curb's line.
    pub bridge_offset_m: f64,
    /// Angle the two tangents may disagree by besides, degrees: the scatter of tangents
    /// taken over 2 m of tracked toe. Not in the paper.
    pub bridge_tangent_tol_deg: f64,

    // ---- Post-filters (end of §2.7) ----
    /// Edges shorter than this are removed, metres. Not in the paper; 1 m is shorter than
    /// any curb stretch worth mapping and longer than most spurious tracks on cars.
    pub min_edge_length_m: f64,
    /// Vehicle filter: lower end of the height band above an edge point, metres. Not in the
    /// paper; above any curb top and most weeds.
    pub vehicle_band_low_m: f64,
    /// Vehicle filter: upper end of the height band, metres. Not in the paper; below street
    /// trees' crowns, above car roofs' edges.
    pub vehicle_band_high_m: f64,
    /// Vehicle filter: horizontal radius around an edge point, metres. Not in the paper; a
    /// car body overhangs its tyres' contact line by about this much.
    pub vehicle_radius_m: f64,
    /// Vehicle filter: an edge is removed when at least this share of its points have points
    /// in the band above them. Not in the paper; a pole or sign next to a curb covers only a
    /// few edge points.
    pub vehicle_share: f64,
    /// Whether the "outside the roadway" filter runs (§2.7: the segment from an edge's end
    /// to its nearest trajectory point crosses another edge of the same side).
    pub roadway_filter: bool,

    // ---- Output ----
    /// Half-width of the moving average over the output vertices (±k vertices, window
    /// shrinking symmetrically at the ends so end points stay put). The tracked points are
    /// measured points, scattered across the toe by the point spacing along the scanline
    /// (1–3 cm near, up to 14 cm far); averaging 5 of them cuts that scatter by about √5
    /// while a 4 m corner radius moves by under 2 mm over the 0.45 m window. Not in the
    /// paper; 0 turns it off.
    pub smooth_half_window: u32,
    /// Moves each output vertex to the peak of a parabola through ρ of its point and its
    /// two neighbours on the same scanline (at most half a point spacing), instead of
    /// leaving it on the measured point. Not in the paper.
    pub refine_peak: bool,

    // ---- Curb height and category (output properties) ----
    /// Width of the strips on either side of an edge point whose median heights give the
    /// height step, metres (starting `step_gap_m` from the edge).
    pub step_strip_m: f64,
    /// Distance from the edge point to the strips, metres (skips the curb face and batter).
    pub step_gap_m: f64,
    /// Height steps under this are a curb cut, metres. Curb cuts drop to 20–30 mm, plain
    /// curbs are 80 mm or more; 50 mm is between.
    pub curb_cut_max_step_m: f64,
    /// Edge pieces turning more than this from the trajectory's heading are an
    /// intersection, degrees. Curbs along the road stay within a few degrees, bus bay tapers
    /// within about 20°, intersection corners turn to 90°.
    pub intersection_angle_deg: f64,
    /// Category runs shorter than this are merged into their neighbours, metres.
    pub min_category_run_m: f64,
}

impl Default for BendParams {
    fn default() -> Self {
        Self {
            seed_interval_m: 2.0,
            ransac_iterations: 64,
            ransac_inlier_m: 0.04,
            ransac_min_inliers: 5,
            ransac_min_inlier_ratio: 0.5,
            ransac_seed: 0x5eed_c0de,
            search_distance_m: 0.15,
            search_radius_m: 0.10,
            search_half_height_m: 0.3,
            alpha: 1.0,
            beta: 3.0,
            gamma: 1.0,
            a: 0.7,
            b: 0.3,
            stop_rho_deg: 10.0,
            min_sigma_rho_deg: 1.0,
            max_gap_steps: 6,
            profile_fallback: true,
            profile_half_width_m: 0.45,
            profile_half_length_m: 0.15,
            profile_min_step_m: 0.05,
            profile_max_slope: 0.1,
            profile_max_road_fall: 0.15,
            profile_seed_reach_m: 15.0,
            leg_toes: true,
            end_view: None,
            cut_follow_max_m: 15.0,
            weak_rho_deg: 30.0,
            weak_run_max_m: 1.5,
            max_steps: 200_000,
            join_distance_m: 0.05,
            bridge_max_m: 12.0,
            bridge_max_turn_deg: 20.0,
            bridge_offset_m: 0.1,
            bridge_tangent_tol_deg: 0.5,
            min_edge_length_m: 1.0,
            vehicle_band_low_m: 0.4,
            vehicle_band_high_m: 2.0,
            vehicle_radius_m: 0.2,
            vehicle_share: 0.3,
            roadway_filter: true,
            smooth_half_window: 2,
            refine_peak: false,
            step_strip_m: 0.25,
            step_gap_m: 0.08,
            curb_cut_max_step_m: 0.05,
            intersection_angle_deg: 30.0,
            min_category_run_m: 1.0,
        }
    }
}

/// The road a spinning sensor sees from each end of its points: the ring points kept from
/// `near_m` to `reach_m` horizontally from the sensor, within `max_azimuth_deg` of straight
/// ahead (at the end) or behind (at the start).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EndView {
    /// Nearest horizontal range of the ring points kept, metres.
    pub near_m: f64,
    /// Farthest range of the ring points kept, metres.
    pub reach_m: f64,
    /// Largest azimuth from the vehicle's axis of the points kept, degrees.
    pub max_azimuth_deg: f64,
}

/// How much wider than `profile_half_width_m` a widened profile is, metres.
pub const WIDE_PROFILE_EXTRA_M: f64 = 0.15;

/// `params` with profiles [`WIDE_PROFILE_EXTRA_M`] wider: the second try of the profile
/// seeds and of a track along the road where profiles of the default width show no toe (a
/// far curb that its scanlines cross at a grazing angle).
pub fn widened(params: &BendParams) -> BendParams {
    BendParams {
        profile_half_width_m: params.profile_half_width_m + WIDE_PROFILE_EXTRA_M,
        ..params.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn toml_round_trip_and_partial_tables_take_defaults() {
        let p = BendParams::default();
        let text = toml::to_string(&p).unwrap();
        let back: BendParams = toml::from_str(&text).unwrap();
        assert_eq!(back, p);
        let partial: BendParams = toml::from_str("search_distance_m = 0.2\n").unwrap();
        assert_eq!(partial.search_distance_m, 0.2);
        assert_eq!(partial.seed_interval_m, p.seed_interval_m);
        assert!(toml::from_str::<BendParams>("no_such_field = 1\n").is_err());
    }
}
