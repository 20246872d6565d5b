//! Filter 2c: a track that turns off the curb along a parked vehicle's end.
//!
//! A track on the curb beside a parked vehicle can turn at the vehicle's end and follow
//! the foot of its end face across the road for a metre or two, and on along the body. The
//! vertices under the body or along its top go by filters 2 and 4, but the turn lies
//! beside the end face, not under it, and stays as a short line across the route. A side
//! street's corner turns as well, but has no vehicle's face beside it; a straight curb
//! beside a vehicle does not turn. So a run of turned vertices (as the categories' test
//! finds them) at most [`HOOK_MAX_M`] long, most of whose vertices have vehicle-high
//! points beside them, spread along it as a vehicle's end face is, not a pole, is cut out of its track; the stretches on either side stay as
//! tracks of their own.

use super::grid::PointGrid;
use super::params::BendParams;
use super::postfilter::{tangent, track_length_m};
use super::route::Route;
use super::track::Track;
use super::BendInput;

/// Longest turned run that is cut, metres: a vehicle's width plus the turn onto its face.
const HOOK_MAX_M: f64 = 3.0;
/// Horizontal radius around a vertex in which vehicle-high points count as beside it,
/// metres: the foot line the bend angle finds lies up to a body's overhang from its face.
const BESIDE_RADIUS_M: f64 = 0.5;
/// Fewest vehicle-high points within [`BESIDE_RADIUS_M`] for a vertex to lie beside one.
const BESIDE_MIN_POINTS: usize = 3;
/// Share of a turned run's vertices beside a vehicle from which it is cut.
const BESIDE_SHARE: f64 = 0.5;
/// Narrowest spread of the vehicle-high points beside a turned run, along it, metres: a
/// vehicle's end is 1.5–2 m wide, a pole or a sign post beside a curb's turn a few
/// decimetres.
const FACE_MIN_WIDTH_M: f64 = 1.0;
/// Half-span of the tangent that decides whether a vertex turned, metres (as the
/// categories' intersection test takes it).
const TURN_HALF_SPAN_M: f64 = 0.5;

/// Points in the vehicle band (`vehicle_band_low_m`..`vehicle_band_high_m` above `q`)
/// within [`BESIDE_RADIUS_M`] of `q`, each given to `f`.
fn vehicle_high_near(
    input: &BendInput,
    grid: &PointGrid,
    q: [f64; 3],
    params: &BendParams,
    mut f: impl FnMut(usize),
) {
    grid.for_each_within(input.x, input.y, q[0], q[1], BESIDE_RADIUS_M, |i| {
        let dz = input.z[i] - q[2];
        if dz >= params.vehicle_band_low_m && dz <= params.vehicle_band_high_m {
            f(i);
        }
    });
}

/// Whether the turned vertices `xyz` run beside a vehicle's end: at least
/// [`BESIDE_SHARE`] of them have [`BESIDE_MIN_POINTS`] vehicle-high points near, and those
/// points spread at least [`FACE_MIN_WIDTH_M`] along the run (a face, not a pole).
fn beside_a_face(
    input: &BendInput,
    grid: &PointGrid,
    xyz: &[[f64; 3]],
    params: &BendParams,
) -> bool {
    let (a, b) = (xyz[0], xyz[xyz.len() - 1]);
    let chord = [b[0] - a[0], b[1] - a[1]];
    let l = chord[0].hypot(chord[1]);
    if l < FACE_MIN_WIDTH_M {
        return false;
    }
    let dir = [chord[0] / l, chord[1] / l];
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut beside = 0;
    for &q in xyz {
        let mut n = 0;
        vehicle_high_near(input, grid, q, params, |i| {
            n += 1;
            let s = (input.x[i] - a[0]) * dir[0] + (input.y[i] - a[1]) * dir[1];
            lo = lo.min(s);
            hi = hi.max(s);
        });
        if n >= BESIDE_MIN_POINTS {
            beside += 1;
        }
    }
    beside as f64 >= BESIDE_SHARE * xyz.len() as f64 && hi - lo >= FACE_MIN_WIDTH_M
}

/// Filter 2c (see the module docs): cuts the short turned runs beside vehicles out of the
/// tracks.
pub fn remove_vehicle_hooks(
    input: &BendInput,
    grid: &PointGrid,
    route: &Route,
    tracks: Vec<Track>,
    params: &BendParams,
) -> Vec<Track> {
    let mut out = Vec::with_capacity(tracks.len());
    for t in tracks {
        let n = t.xyz.len();
        if n < 2 {
            out.push(t);
            continue;
        }
        let xy: Vec<[f64; 2]> = t.xyz.iter().map(|q| [q[0], q[1]]).collect();
        let turned: Vec<bool> = (0..n)
            .map(|k| {
                tangent(&xy, k, TURN_HALF_SPAN_M)
                    .zip(route.nearest(xy[k][0], xy[k][1]))
                    .is_some_and(|(tan, (_, f))| {
                        let c = (tan[0] * f[0] + tan[1] * f[1]).abs().min(1.0);
                        c.acos().to_degrees() > params.intersection_angle_deg
                    })
            })
            .collect();
        // Every maximal run of turned vertices that is a hook is cut out; the stretches
        // between stay as tracks of their own.
        let mut cut = vec![false; n];
        let mut k = 0;
        while k < n {
            if !turned[k] {
                k += 1;
                continue;
            }
            let lo = k;
            while k < n && turned[k] {
                k += 1;
            }
            let len: f64 = xy[lo..k]
                .windows(2)
                .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
                .sum();
            if len > HOOK_MAX_M {
                continue;
            }
            if beside_a_face(input, grid, &t.xyz[lo..k], params) {
                cut[lo..k].iter_mut().for_each(|c| *c = true);
            }
        }
        if !cut.contains(&true) {
            out.push(t);
            continue;
        }
        let mut k = 0;
        while k < n {
            if cut[k] {
                k += 1;
                continue;
            }
            let lo = k;
            while k < n && !cut[k] {
                k += 1;
            }
            let piece = Track {
                points: t.points[lo..k].to_vec(),
                xyz: t.xyz[lo..k].to_vec(),
                side: t.side,
            };
            if track_length_m(input, &piece) >= params.min_edge_length_m {
                out.push(piece);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bend::fixture::{drive_along_x, KeptPoints};
    use crate::model::Side;

    /// Vertices 0.1 m apart on the road's level from `a` to `b`.
    fn run(a: [f64; 2], b: [f64; 2]) -> Vec<[f64; 3]> {
        let len = (b[0] - a[0]).hypot(b[1] - a[1]);
        let m = (len / 0.1).round() as usize;
        (0..m)
            .map(|k| {
                let f = k as f64 / m as f64;
                [a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]), 0.0]
            })
            .collect()
    }

    fn track(xyz: Vec<[f64; 3]>) -> Track {
        Track {
            points: (0..xyz.len() as u32).collect(),
            xyz,
            side: Side::Left,
        }
    }

    /// `remove_vehicle_hooks` with the defaults on `tracks` beside `points`, along a drive
    /// east along y = 0.
    fn without_hooks(points: &KeptPoints, tracks: Vec<Track>) -> Vec<Track> {
        let traj = drive_along_x(0.0);
        let input = points.input(&traj);
        let grid = PointGrid::build(input.x, input.y, 0.1, |_| true);
        let route = Route::new(&traj);
        remove_vehicle_hooks(&input, &grid, &route, tracks, &BendParams::default())
    }

    #[test]
    fn a_turn_along_a_vehicles_end_is_cut_and_a_corner_stays() {
        // A curb 3 m left of the drive from x = 0 to 10; a car parked on the road beyond
        // x = 10.1, its body 0.5–1.5 m up between y = 1 and 2.8 (its end face's returns
        // 5 cm apart). A track along the curb turns at x = 10 along the foot of the car's
        // end (y 3 → 1, 2 m), then runs along its side to x = 15.
        let (mut x, mut y, mut z) = (Vec::new(), Vec::new(), Vec::new());
        for iy in 0..=36 {
            for iz in 0..=20 {
                x.push(10.1);
                y.push(1.0 + 0.05 * f64::from(iy));
                z.push(0.5 + 0.05 * f64::from(iz));
            }
        }
        let points = KeptPoints::new(x, y, z);
        let hooked: Vec<[f64; 3]> = run([0.0, 3.0], [10.0, 3.0])
            .into_iter()
            .chain(run([10.0, 3.0], [10.0, 1.0]))
            .chain(run([10.0, 1.0], [15.0, 1.0]))
            .collect();
        let kept = without_hooks(&points, vec![track(hooked.clone())]);
        assert_eq!(kept.len(), 2, "{kept:?}");
        // Nothing of the turn is left: every vertex lies along the drive, on the curb or
        // the car's side, within the tangent's half-span of the corner.
        for t in &kept {
            assert!(t
                .xyz
                .iter()
                .all(|q| q[1] >= 3.0 - TURN_HALF_SPAN_M || q[1] <= 1.0 + TURN_HALF_SPAN_M));
        }
        assert!(kept[0].xyz.iter().all(|q| q[1] == 3.0) && kept[0].xyz.len() > 90);
        // The same turn with no vehicle beside it (a side street's corner) stays whole.
        let bare = KeptPoints::new(vec![], vec![], vec![]);
        let kept = without_hooks(&bare, vec![track(hooked.clone())]);
        assert_eq!(kept, vec![track(hooked)]);
    }

    #[test]
    fn a_short_turn_beside_a_pole_stays() {
        // A curb that steps 1.2 m towards the road at x = 10 (a kerb line's jog), a pole
        // 0.2 m across, 0.5–2.5 m up, beside the step: most of the turned vertices have
        // the pole's points near, but they spread 0.2 m, not a vehicle's width.
        let (mut x, mut y, mut z) = (Vec::new(), Vec::new(), Vec::new());
        for k in 0..=20 {
            for (dx, dy) in [(0.0, 0.0), (0.2, 0.0), (0.1, 0.1), (0.1, -0.1)] {
                x.push(10.2 + dx);
                y.push(2.4 + dy);
                z.push(0.5 + 0.1 * f64::from(k));
            }
        }
        let points = KeptPoints::new(x, y, z);
        let jog = track(
            run([0.0, 3.0], [10.0, 3.0])
                .into_iter()
                .chain(run([10.0, 3.0], [10.0, 1.8]))
                .chain(run([10.0, 1.8], [15.0, 1.8]))
                .collect(),
        );
        let kept = without_hooks(&points, vec![jog.clone()]);
        assert_eq!(kept, vec![jog]);
    }

    #[test]
    fn a_straight_curb_beside_a_vehicle_stays() {
        // The car's side 0.2 m from a straight curb, its body 0.5–1.5 m up: no turn.
        let (mut x, mut y, mut z) = (Vec::new(), Vec::new(), Vec::new());
        for ix in 0..=100 {
            for iz in 0..=20 {
                x.push(0.05 * f64::from(ix));
                y.push(2.8);
                z.push(0.5 + 0.05 * f64::from(iz));
            }
        }
        let points = KeptPoints::new(x, y, z);
        let curb = track(run([0.0, 3.0], [5.0, 3.0]));
        let kept = without_hooks(&points, vec![curb.clone()]);
        assert_eq!(kept, vec![curb]);
    }
}
