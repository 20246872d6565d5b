//! The bend-angle method's host half (Honma et al. §2.6–2.7): seeding by RANSAC per
//! interval ([`seed`]), tracking by the energy of Eq. 4–8 ([`track`]), virtual toes
//! moved across the curb's shadow ([`shadow`]), post-filters and the edges' properties
//! ([`postfilter`]), bridges between tracks that continue each other ([`bridge`]). It
//! reads the core's output as it is (its ρ and
//! its candidates) and never recomputes them.
//!
//! Everything here is sequential and uses only seeded randomness, so the output is the same
//! on every run and whatever the thread count.

use crate::io::trajectory::Trajectory;
use crate::model::EdgeLine;
use crate::replay::{Candidate, PointStatus};

pub mod arc_seed;
pub mod bridge;
pub mod claims;
pub mod climb;
pub mod face;
pub mod flush;
pub mod grid;
pub mod hole;
pub mod hook;
pub mod leg;
pub mod leg_screen;
pub mod leg_seed;
pub mod params;
pub mod postfilter;
pub mod profile;
pub mod route;
pub mod seed;
pub mod shadow;
pub mod sparse;
pub mod track;

pub use params::{BendParams, EndView};

/// Everything the host half of the bend method reads. All slices are indexed by point
/// (the columns of `io::las_in`, sorted by time).
pub struct BendInput<'a> {
    /// World X, metres.
    pub x: &'a [f64],
    /// World Y, metres.
    pub y: &'a [f64],
    /// World Z, metres.
    pub z: &'a [f64],
    /// GPS time, seconds.
    pub t: &'a [f64],
    /// Bend angle on the smoothed scanline from the core, degrees (0 unless kept).
    pub rho_deg: &'a [f32],
    /// The core's status per point; `None` for points the core never returned.
    pub status: &'a [Option<PointStatus>],
    /// Scanline number per point, meaningful where the status is `Some`.
    pub scanline: &'a [u32],
    /// The core's seed candidates.
    pub candidates: &'a [Candidate],
    /// The trajectory.
    pub trajectory: &'a Trajectory,
}

impl<'a> BendInput<'a> {
    /// The same input with every column cut to the shortest column's length, so that no
    /// index taken from one column can fall outside another.
    fn truncated(&self) -> BendInput<'a> {
        let n = [
            self.x.len(),
            self.y.len(),
            self.z.len(),
            self.t.len(),
            self.rho_deg.len(),
            self.status.len(),
            self.scanline.len(),
        ]
        .into_iter()
        .min()
        .unwrap_or(0);
        BendInput {
            x: &self.x[..n],
            y: &self.y[..n],
            z: &self.z[..n],
            t: &self.t[..n],
            rho_deg: &self.rho_deg[..n],
            status: &self.status[..n],
            scanline: &self.scanline[..n],
            candidates: self.candidates,
            trajectory: self.trajectory,
        }
    }
}

/// Extracts the road edges (Honma et al. §2.6–2.7): seeds by RANSAC per interval, tracks
/// from every seed in both directions, removes short edges, edges under vehicles, edges
/// along gaps in the returns and edges outside the roadway, and returns each edge once
/// with `method = "bend"`, its side, its median height step and a category per stretch.
pub fn extract_edges(input: &BendInput, params: &BendParams) -> Vec<EdgeLine> {
    extract_edges_with_steps(input, params)
        .into_iter()
        .map(|(e, _)| e)
        .collect()
}

/// [`extract_edges`], with each edge's height step per vertex (see
/// [`postfilter::to_edge_lines_with_steps`]).
pub fn extract_edges_with_steps(
    input: &BendInput,
    params: &BendParams,
) -> Vec<(EdgeLine, Vec<Option<f64>>)> {
    extract_edges_on_route(input, &route::Route::new(input.trajectory), params)
}

/// [`extract_edges_with_steps`] on a route built once from `input.trajectory` (a stream
/// runs many windows over one trajectory). Filter 4 ([`postfilter::remove_tall_steps`])
/// runs here on whole edges; a stream runs it where its pieces are joined, on the median
/// over the whole edge (`stream::merge`).
pub fn extract_edges_on_route(
    input: &BendInput,
    route: &route::Route,
    params: &BendParams,
) -> Vec<(EdgeLine, Vec<Option<f64>>)> {
    postfilter::remove_tall_steps(extract_edges_on_grid(
        input,
        &point_grid(input, params),
        route,
        params,
    ))
}

/// The one index over every processed point that the tracker and the curb annotation
/// share: tracking reads the kept points, the vehicle filter, the height step and the
/// cross-sections of [`crate::curb::annotate`] read all. Cells of the search radius
/// (5 cm to 1 m).
pub fn point_grid(input: &BendInput, params: &BendParams) -> grid::PointGrid {
    let mut g = grid::PointGrid::build(&[], &[], 1.0, |_| false);
    point_grid_into(&mut g, input, params);
    g
}

/// [`point_grid`] built in `grid`'s arrays (a stream's window reuses one grid for every
/// section).
pub fn point_grid_into(grid: &mut grid::PointGrid, input: &BendInput, params: &BendParams) {
    let input = input.truncated();
    let cell_m = params.search_radius_m.clamp(0.05, 1.0);
    grid.rebuild(input.x, input.y, cell_m, |i| input.status[i].is_some());
}

/// [`point_grid_into`] for a window of a stream whose index 0 is the stream's point
/// `origin`: the slabs of `grid` that the window still holds are kept and only its new
/// points indexed, in slabs cut at `cut`, where the next window will begin
/// ([`grid::PointGrid::slide`]).
pub fn point_grid_slide(
    grid: &mut grid::PointGrid,
    input: &BendInput,
    origin: u64,
    cut: Option<usize>,
    params: &BendParams,
) {
    let input = input.truncated();
    let cell_m = params.search_radius_m.clamp(0.05, 1.0);
    grid.slide(input.x, input.y, origin, cut, cell_m, |i| {
        input.status[i].is_some()
    });
}

/// [`extract_edges_on_route`] on `grid`, the [`point_grid`] of `input`.
pub fn extract_edges_on_grid(
    input: &BendInput,
    grid: &grid::PointGrid,
    route: &route::Route,
    params: &BendParams,
) -> Vec<(EdgeLine, Vec<Option<f64>>)> {
    let input = input.truncated();
    let mut seeds = seed::seed_points(&input, route, params);
    let from_profiles = seed::profile_seeds(&input, grid, route, params);
    seeds.extend(from_profiles);
    seeds.extend(seed::end_seeds(&input, grid, route, params));
    // Best-fitting seeds first: the first track along a curb claims it, later seeds on the
    // same curb start nothing.
    seeds.sort_by(|a, b| {
        b.inlier_ratio
            .total_cmp(&a.inlier_ratio)
            .then(a.side.cmp(&b.side))
            .then(a.interval.cmp(&b.interval))
            .then(a.point.cmp(&b.point))
    });
    // Seeds on side streets' legs come after all others: they start tracks only on curbs
    // that no other seed's track reaches.
    seeds.extend(leg_seed::leg_seeds(&input, grid, route, params));
    let (mut tracks, tails) = track::track_edges_with_tails(&input, grid, &seeds, params);
    shadow::place_shadowed_toes(&input, grid, &mut tracks, params);
    let tracks = postfilter::remove_short(&input, tracks, params);
    let tracks = postfilter::remove_under_objects(&input, grid, tracks, params);
    let tracks = postfilter::remove_at_return_gaps(&input, grid, tracks, params);
    let tracks = if params.roadway_filter {
        postfilter::remove_outside_roadway(&input, route, tracks)
    } else {
        tracks
    };
    // Virtual vertices of the bridges count on from the tracker's.
    let next_id = tracks
        .iter()
        .flat_map(|t| t.points.iter().copied())
        .chain(tails.iter().flat_map(|t| t.verts.iter().map(|v| v.0)))
        .max()
        .map_or(0, |m| m.saturating_add(1))
        .max(input.x.len() as u32);
    let tracks = bridge::bridge_tracks(&input, grid, tracks, next_id, params);
    // Runs of flush toes go back on the ends no bridge continues.
    let tracks = track::attach_tails(tracks, tails);
    // Turns off the curb along a parked vehicle's end go (filter 2c).
    let tracks = hook::remove_vehicle_hooks(&input, grid, route, tracks, params);
    postfilter::to_edge_lines_with_steps(&input, grid, route, &tracks, params)
}

/// The median of `v` (reordered in place), `None` when empty.
pub fn median(v: &mut [f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_unstable_by(|a, b| a.total_cmp(b));
    let m = v.len() / 2;
    Some(if v.len() % 2 == 1 {
        v[m]
    } else {
        0.5 * (v[m - 1] + v[m])
    })
}

#[cfg(test)]
mod fixture;
#[cfg(test)]
mod tests;
