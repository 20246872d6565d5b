//! Virtual toes across the curb's shadow. Where the scanlines run along a curb seen from
//! behind (a side street's curb seen from the main road past the corner), the raised curb
//! hides the road just before the toe, and a virtual profile ([`Profile::toe`]) holds no
//! road points there: its toe, half-way between the last road and the first curb point,
//! lies on the road. The tracker follows the toes as found (its search positions stay on
//! the line it has followed); afterwards each virtual vertex is moved across, towards the
//! curb, by the shift [`Profile::shadow_shift`] finds on the profile through it. Measured
//! vertices and vertices whose profile shows no shadow stay where they are.

use super::grid::PointGrid;
use super::params::BendParams;
use super::profile::Profile;
use super::track::Track;
use super::BendInput;

/// Farthest the toe found on the profile through a virtual vertex may lie from it for the
/// profile to be that vertex's, metres.
const SAME_TOE_M: f64 = 0.05;

/// Moves every virtual vertex (an id at or past the number of points) of `tracks` across
/// the curb's shadow (see the module docs). The profile through a vertex runs across the
/// track's direction there (its neighbours'); the curb may rise on either side of it, and
/// the side whose profile finds the vertex's toe is taken.
pub fn place_shadowed_toes(
    input: &BendInput,
    grid: &PointGrid,
    tracks: &mut [Track],
    params: &BendParams,
) {
    let n_points = input.x.len();
    let l = params.profile_half_length_m;
    for t in tracks.iter_mut() {
        let m = t.xyz.len();
        let moved: Vec<Option<[f64; 3]>> = (0..m)
            .map(|k| {
                if (t.points[k] as usize) < n_points || m < 2 {
                    return None;
                }
                let (p, q) = (t.xyz[k.saturating_sub(1)], t.xyz[(k + 1).min(m - 1)]);
                let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
                let len = dx.hypot(dy);
                if len < 1e-6 {
                    return None;
                }
                let along = [dx / len, dy / len];
                let v = t.xyz[k];
                for up in [1.0, -1.0] {
                    for half_l in [l, 2.0 * l] {
                        let profile = Profile {
                            input,
                            grid,
                            params,
                            centre: v,
                            along,
                            up,
                            half_l,
                        };
                        let Some((toe, shift)) = profile.shadow_shift() else {
                            continue;
                        };
                        if (toe.xyz[0] - v[0]).hypot(toe.xyz[1] - v[1]) > SAME_TOE_M {
                            continue;
                        }
                        let n = [-along[1] * up, along[0] * up];
                        return (shift > 0.0)
                            .then(|| [v[0] + shift * n[0], v[1] + shift * n[1], v[2]]);
                    }
                }
                None
            })
            .collect();
        for (k, v) in moved.into_iter().enumerate() {
            if let Some(v) = v {
                t.xyz[k] = v;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bend::fixture::KeptPoints;
    use crate::io::trajectory::{Pose, Trajectory};
    use crate::model::Side;

    /// A curb along y with its toe at x = 0 (road x < 0 at z 0, sidewalk 0.12 m up),
    /// scanned by lines along y, one every 0.05 m across; no road returns in the
    /// 0.25 m before the toe, the first curb line 0.01 m behind it. The scanner stands at x = `scanner_x` throughout. Returns
    /// the x of a track's vertices along x = −0.12 (half-way across the gap, where the
    /// tracker's profile puts the toe) after the shadow step: the first vertex measured
    /// (the id of a point), the rest virtual.
    fn placed(scanner_x: f64) -> Vec<f64> {
        let (mut x, mut y, mut z, mut line) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        // Road lines at −0.55 … −0.25, curb lines at 0.01 … 0.31.
        let offsets = (0..7).map(|k| -0.55 + 0.05 * k as f64);
        let offsets = offsets.chain((0..7).map(|k| 0.01 + 0.05 * k as f64));
        for (k, c) in offsets.enumerate() {
            for j in 0..60 {
                x.push(c);
                y.push(-1.5 + 0.05 * j as f64);
                z.push(if c > 0.0 { 0.12 } else { 0.0 });
                line.push(k as u32);
            }
        }
        let n = x.len();
        let t: Vec<f64> = (0..n).map(|i| i as f64 * 1e-4).collect();
        let kept = KeptPoints {
            t,
            scanline: line,
            ..KeptPoints::new(x, y, z)
        };
        let pose = |t: f64| Pose {
            t,
            x: scanner_x,
            y: 0.0,
            z: 2.5,
            roll_deg: 0.0,
            pitch_deg: 0.0,
            heading_deg: 0.0,
        };
        let trajectory = Trajectory {
            samples: vec![pose(-1.0), pose(10.0)],
        };
        let input = kept.input(&trajectory);
        let grid = PointGrid::build(input.x, input.y, 0.1, |_| true);
        let xyz: Vec<[f64; 3]> = (0..6)
            .map(|k| [-0.12, -0.5 + 0.15 * k as f64, 0.0])
            .collect();
        let mut points = vec![0u32];
        points.extend((0..5).map(|k| n as u32 + k));
        let mut tracks = vec![Track {
            points,
            xyz,
            side: Side::Right,
        }];
        place_shadowed_toes(&input, &grid, &mut tracks, &BendParams::default());
        tracks[0].xyz.iter().map(|v| v[0]).collect()
    }

    #[test]
    fn virtual_toes_across_the_curbs_shadow_move_towards_the_curb() {
        // Seen from behind the curb (x > 0): the gap is the curb's shadow; each virtual
        // vertex moves half-way from the gap's middle (−0.12) to the first curb return
        // (0.01), the measured one stays.
        let behind = placed(5.0);
        assert_eq!(behind[0], -0.12);
        assert!(
            behind[1..].iter().all(|&x| (x - -0.055).abs() < 0.005),
            "{behind:?}"
        );
        // Seen from the road: the gap is a gap in the returns; nothing moves.
        let front = placed(-5.0);
        assert!(front.iter().all(|&x| x == -0.12), "{front:?}");
    }
}
