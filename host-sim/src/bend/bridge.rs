//! Bridges across stretches where the toe gives the tracker nothing to follow: curb cuts
//! whose lip is too low for a bend angle (the toe is only a change of slope there) and curb
//! hidden behind a parked vehicle. The curb on either side is tracked; where two tracks of
//! one side end facing each other, and continue each other's line (a straight or a circular
//! arc through both ends with the tangents measured there), the stretch between them is
//! filled by that arc.
//!
//! A bridge must run over measured ground: along most of it there are returns at the
//! height of the line between the two ends. Where the line crosses an area the scanner did
//! not see (behind a vehicle, the mouth of a side street seen past its corner) or runs
//! through something standing on the road, nothing is bridged. Only the tracks and the
//! points near the bridge are read, so a bridge needs nothing beyond the window that holds
//! both tracks.

use super::grid::PointGrid;
use super::params::BendParams;
use super::profile::usable;
use super::track::Track;
use super::BendInput;

/// One end of a track: the vertex and the outward tangent (horizontal unit vector, pointing
/// away from the track).
#[derive(Clone, Copy, Debug)]
struct End {
    track: usize,
    /// Whether this is the track's last vertex (else its first).
    last: bool,
    xyz: [f64; 3],
    out: [f64; 2],
    /// Length of track the tangent was taken over, metres.
    span: f64,
    /// Vertices of the track beyond this end (those of a hook left out, see [`unhooked`]).
    drop: usize,
    /// The end before the track's hook, when it has one (see [`unhooked`]).
    inner: Option<Inner>,
}

/// The end of a track before its last [`END_HOOK_M`]: the vertex, the outward tangent over
/// [`TANGENT_SPAN_M`] of track before it, that length, and the vertices after it.
#[derive(Clone, Copy, Debug)]
struct Inner {
    xyz: [f64; 3],
    out: [f64; 2],
    span: f64,
    drop: usize,
}

impl End {
    /// This end, or the one before the track's hook where it has one.
    fn unhooked(&self) -> End {
        match self.inner {
            Some(i) => End {
                xyz: i.xyz,
                out: i.out,
                span: i.span,
                drop: i.drop,
                inner: None,
                ..*self
            },
            None => *self,
        }
    }
}

/// Track length from an end over which its tangent is taken, metres: long enough to average
/// the vertices' scatter, short enough to follow a 30 m radius.
const TANGENT_SPAN_M: f64 = 2.0;

/// Spacing of the vertices put on a bridge, metres (the tracker's search distance).
const BRIDGE_STEP_M: f64 = 0.15;

/// The end of `t` (its last vertex when `last`) with its outward tangent over
/// [`TANGENT_SPAN_M`] of track; `None` when the track is shorter than half of that.
fn end_of(t: &Track, track: usize, last: bool) -> Option<End> {
    let n = t.xyz.len();
    if n < 2 {
        return None;
    }
    let at = |k: usize| if last { t.xyz[n - 1 - k] } else { t.xyz[k] };
    let e = at(0);
    let mut far = None;
    let mut along = 0.0;
    for k in 1..n {
        let (a, b) = (at(k - 1), at(k));
        along += (b[0] - a[0]).hypot(b[1] - a[1]);
        far = Some(b);
        if along >= TANGENT_SPAN_M {
            break;
        }
    }
    let f = far?;
    if along < 0.5 * TANGENT_SPAN_M {
        return None;
    }
    let (dx, dy) = (e[0] - f[0], e[1] - f[1]);
    let l = dx.hypot(dy);
    (l > 1e-6).then(|| End {
        track,
        last,
        xyz: e,
        out: [dx / l, dy / l],
        span: along,
        drop: 0,
        inner: unhooked(t, last),
    })
}

/// Length of track at an end that may hook off the curb's line, metres: where the toe a
/// track follows fades (a cut's transition lowering the curb), the kernel's peak slides
/// towards the road over the last few vertices.
const END_HOOK_M: f64 = 0.5;

/// Least distance of a track's end from the line of the track before [`END_HOOK_M`] for
/// the end to be a hook, metres: over the toe's own scatter along a track.
const END_HOOK_MIN_M: f64 = 0.03;

/// Farthest a vertex of the track before the hook may lie from its tangent's line for the
/// end to be a hook, metres: on a track that wanders by as much (sparse returns, bridged
/// stretches) an end that does is no hook.
const END_HOOK_STEADY_M: f64 = 0.03;

/// The end of `t` (its last vertex when `last`) before a hook: the vertex [`END_HOOK_M`]
/// back from the end with its outward tangent over [`TANGENT_SPAN_M`] of track, when the
/// end lies at least [`END_HOOK_MIN_M`] off that tangent's line; `None` when the end does
/// not hook or the track is too short to tell.
///
/// A bridge from the hook's end with the hook's tangent runs off a straight curb by
/// as much as the hook and more (its arc turns with the tangent); from the vertex before
/// the hook it continues the curb's line.
fn unhooked(t: &Track, last: bool) -> Option<Inner> {
    let n = t.xyz.len();
    let at = |k: usize| if last { t.xyz[n - 1 - k] } else { t.xyz[k] };
    let mut along = 0.0;
    let mut k = 0;
    while along < END_HOOK_M {
        k += 1;
        if k >= n {
            return None;
        }
        let (a, b) = (at(k - 1), at(k));
        along += (b[0] - a[0]).hypot(b[1] - a[1]);
    }
    let (e, from) = (at(k), along);
    let mut far = None;
    for j in k + 1..n {
        let (a, b) = (at(j - 1), at(j));
        along += (b[0] - a[0]).hypot(b[1] - a[1]);
        far = Some(b);
        if along - from >= TANGENT_SPAN_M {
            break;
        }
    }
    let f = far?;
    let span = along - from;
    let (dx, dy) = (e[0] - f[0], e[1] - f[1]);
    let l = dx.hypot(dy);
    if span < 0.5 * TANGENT_SPAN_M || l <= 1e-6 {
        return None;
    }
    let out = [dx / l, dy / l];
    let off = |q: [f64; 3]| (out[0] * (q[1] - e[1]) - out[1] * (q[0] - e[0])).abs();
    let steady = (k..n)
        .map(at)
        .take_while(|&q| q != f)
        .all(|q| off(q) <= END_HOOK_STEADY_M);
    (steady && off(at(0)) >= END_HOOK_MIN_M).then_some(Inner {
        xyz: e,
        out,
        span,
        drop: k,
    })
}

/// Signed angle from unit vector `a` to unit vector `b`, radians.
fn angle(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] * b[1] - a[1] * b[0]).atan2(a[0] * b[0] + a[1] * b[1])
}

/// Whether segments ab and cd cross.
fn crosses(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> bool {
    let orient = |p: [f64; 2], q: [f64; 2], r: [f64; 2]| {
        (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])
    };
    let (d1, d2) = (orient(c, d, a), orient(c, d, b));
    let (d3, d4) = (orient(a, b, c), orient(a, b, d));
    d1 * d2 < 0.0 && d3 * d4 < 0.0
}

/// How well ends `a` and `b` continue each other: the bridge's length and the angle from
/// the chord a → b to the arc's tangent at `a` (left positive), when they face each other
/// across at most `bridge_max_m` and a straight or circular arc through both fits their
/// tangents (the turn from the chord at `a` mirrors the one at `b`, to within the angle a
/// lateral offset of `bridge_offset_m` makes over the chord).
fn fit(a: &End, b: &End, params: &BendParams) -> Option<(f64, f64)> {
    let c = [b.xyz[0] - a.xyz[0], b.xyz[1] - a.xyz[1]];
    let d = c[0].hypot(c[1]);
    if d < 1e-6 || d > params.bridge_max_m {
        return None;
    }
    let u = [c[0] / d, c[1] / d];
    // For an arc, a's outward tangent turns from the chord by −φ and b's from the reversed
    // chord by +φ.
    let pa = angle(u, a.out);
    let pb = angle([-u[0], -u[1]], b.out);
    let max_turn = params.bridge_max_turn_deg.to_radians();
    if pa.abs() > max_turn || pb.abs() > max_turn {
        return None;
    }
    let tol = 2.0 * params.bridge_offset_m / d + params.bridge_tangent_tol_deg.to_radians();
    if (pa + pb).abs() > tol {
        return None;
    }
    // Each tangent is the chord of the track over its span, which on an arc turns from the
    // chord a → b by (d + span) / 2R rather than d / 2R.
    let span = 0.5 * (a.span + b.span);
    Some((d, 0.5 * (pa - pb) * d / (d + span)))
}

/// The point at fraction `s` of the circular arc from `a` to `b` whose tangent at `a` turns
/// `alpha` from the chord (left positive; 0: the straight chord).
fn on_arc(a: [f64; 3], b: [f64; 3], alpha: f64, s: f64) -> [f64; 3] {
    let z = a[2] + s * (b[2] - a[2]);
    let c = [b[0] - a[0], b[1] - a[1]];
    if alpha.abs() < 1e-6 {
        return [a[0] + s * c[0], a[1] + s * c[1], z];
    }
    let d = c[0].hypot(c[1]);
    let (u, n) = ([c[0] / d, c[1] / d], [-c[1] / d, c[0] / d]);
    // Chord-centred coordinates: along = R sin ψ, across = R (cos ψ − cos φ) towards the
    // bulge, for ψ from −φ to φ.
    let phi = alpha.abs();
    let r = d / (2.0 * phi.sin());
    let psi = -phi + 2.0 * phi * s;
    let along = r * psi.sin();
    let across = alpha.signum() * r * (psi.cos() - phi.cos());
    let m = [a[0] + 0.5 * c[0], a[1] + 0.5 * c[1]];
    [
        m[0] + along * u[0] + across * n[0],
        m[1] + along * u[1] + across * n[1],
        z,
    ]
}

/// Length of each track beside a bridge over which the curb's line is fitted, metres:
/// three times [`TANGENT_SPAN_M`], so that the toe's scatter and its drift over the last
/// metres (where a cut lowers the curb) weigh little against the curb's own line.
const CURVE_FIT_SPAN_M: f64 = 6.0;

/// Largest turn from the chord at either end, from the ends' tangents, for which a bridge
/// is laid by [`curb_line_fit`], degrees: a curb that continues across the bridge with a
/// bend of a large radius; a sharper turn (an intersection's corner) keeps the tangents'
/// arc.
const CURVE_FIT_MAX_TURN_DEG: f64 = 4.0;

/// Least distance from the fitted line of a track's end vertex that drifted off it,
/// metres: over the toe's scatter along most tracks.
const DRIFT_MIN_M: f64 = 0.025;

/// Longest drift at a track's end that is left out of a bridge, metres: a cut's
/// transition and the first metre of its lowered part.
const DRIFT_MAX_M: f64 = 2.0;

/// Largest difference between the curvatures of the two tracks' own fits for one fit
/// over both to be used, 1/m: a 50 m radius against a straight curb; over the noise of
/// a curvature fitted to a few metres of scattered toe.
const CURVE_FIT_MAX_BEND_DIFF: f64 = 0.02;

/// Largest root-mean-square distance of the vertices left from the fitted line for the
/// fit to be used, metres: over the toe's scatter along a track.
const CURVE_FIT_MAX_RMS_M: f64 = 0.02;

/// The vertices of `t` from the end `e` (past its dropped hook) inwards over
/// [`CURVE_FIT_SPAN_M`] of track, each with its length of track from the end.
fn fit_vertices(t: &Track, e: &End) -> Vec<([f64; 3], f64)> {
    let n = t.xyz.len();
    let at = |k: usize| if e.last { t.xyz[n - 1 - k] } else { t.xyz[k] };
    let mut out: Vec<([f64; 3], f64)> = Vec::new();
    for k in e.drop..n {
        let q = at(k);
        let along = out
            .last()
            .map_or(0.0, |&(p, l)| l + (q[0] - p[0]).hypot(q[1] - p[1]));
        if along > CURVE_FIT_SPAN_M {
            break;
        }
        out.push((q, along));
    }
    out
}

/// Least-squares parabola y = p + q·x + c·x² through `xy`; `None` when singular.
fn parabola(xy: &[(f64, f64)]) -> Option<[f64; 3]> {
    let mut s = [0.0f64; 5];
    let mut t = [0.0f64; 3];
    for &(x, y) in xy {
        let mut xk = 1.0;
        for (k, sk) in s.iter_mut().enumerate() {
            *sk += xk;
            if k < 3 {
                t[k] += xk * y;
            }
            xk *= x;
        }
    }
    let mat = [[s[0], s[1], s[2]], [s[1], s[2], s[3]], [s[2], s[3], s[4]]];
    let det3 = |m: &[[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let det = det3(&mat);
    if det.is_nan() || det.abs() <= 1e-12 * s[0].powi(3) {
        return None;
    }
    // Cramer's rule, column by column.
    let solve = |col: usize| {
        let mut mk = mat;
        for (row, tk) in mk.iter_mut().zip(t) {
            row[col] = tk;
        }
        det3(&mk) / det
    };
    Some([solve(0), solve(1), solve(2)])
}

/// The bridge between the tracks of ends `a` and `b` laid on the curb's line as both
/// tracks give it: a parabola across the chord fitted to [`CURVE_FIT_SPAN_M`] of each
/// track; the vertices at either end that drifted off it (at least [`DRIFT_MIN_M`], over
/// at most [`DRIFT_MAX_M`] of track) are left out and the fit made again without them.
/// Returns the new ends, the chord between them and the turn from the chord at the first
/// (left positive, as [`fit`] gives it) of the arc with the parabola's curvature. `None`
/// when either track keeps fewer than three vertices, the fit is singular or the vertices
/// left lie farther than [`CURVE_FIT_MAX_RMS_M`] from it (the curb bends in another way
/// than one arc).
///
/// Where a cut lowers the curb the toe a track follows fades and the kernel's peak drifts
/// off the curb's line over the last metres; tangents over those metres tilt, and an arc
/// from the drifted ends with them runs off a straight curb by the drift and more.
fn curb_line_fit(ta: &Track, a: &End, tb: &Track, b: &End) -> Option<(End, End, f64, f64)> {
    let c = [b.xyz[0] - a.xyz[0], b.xyz[1] - a.xyz[1]];
    let d = c[0].hypot(c[1]);
    if d < 1e-6 {
        return None;
    }
    let (u, nrm) = ([c[0] / d, c[1] / d], [-c[1] / d, c[0] / d]);
    // Chord-centred coordinates, x scaled so the normal equations stay well conditioned.
    let m = [a.xyz[0] + 0.5 * c[0], a.xyz[1] + 0.5 * c[1]];
    let h = 0.5 * d + CURVE_FIT_SPAN_M;
    let local = |q: [f64; 3]| {
        let (dx, dy) = (q[0] - m[0], q[1] - m[1]);
        ((dx * u[0] + dy * u[1]) / h, dx * nrm[0] + dy * nrm[1])
    };
    let (va, vb) = (fit_vertices(ta, a), fit_vertices(tb, b));
    let (la, lb): (Vec<_>, Vec<_>) = (
        va.iter().map(|&(q, _)| local(q)).collect(),
        vb.iter().map(|&(q, _)| local(q)).collect(),
    );
    let (mut ka, mut kb) = (0usize, 0usize);
    let mut coef = None;
    for _ in 0..3 {
        if va.len() < ka + 3 || vb.len() < kb + 3 {
            return None;
        }
        let pts: Vec<(f64, f64)> = la[ka..].iter().chain(&lb[kb..]).copied().collect();
        let f = parabola(&pts)?;
        let off = |&(x, y): &(f64, f64)| (y - f[0] - f[1] * x - f[2] * x * x).abs();
        let drift = |v: &[([f64; 3], f64)], l: &[(f64, f64)]| {
            v.iter()
                .zip(l)
                .take_while(|((_, along), xy)| *along <= DRIFT_MAX_M && off(xy) >= DRIFT_MIN_M)
                .count()
        };
        let (na, nb) = (drift(&va, &la), drift(&vb, &lb));
        coef = Some((f, pts));
        if (na, nb) == (ka, kb) {
            break;
        }
        (ka, kb) = (na, nb);
    }
    let (f, pts) = coef?;
    if va.len() < ka + 3 || vb.len() < kb + 3 {
        return None;
    }
    // Both tracks bend alike: a curb that bends on one side of the bridge and runs
    // straight on the other (a corner's arc meeting the straight curb at a cut) is not one
    // arc.
    let (fa, fb) = (parabola(&la[ka..])?, parabola(&lb[kb..])?);
    if 2.0 * (fa[2] - fb[2]).abs() / (h * h) > CURVE_FIT_MAX_BEND_DIFF {
        return None;
    }
    let rss: f64 = pts
        .iter()
        .map(|&(x, y)| (y - f[0] - f[1] * x - f[2] * x * x).powi(2))
        .sum();
    if (rss / pts.len() as f64).sqrt() > CURVE_FIT_MAX_RMS_M {
        return None;
    }
    let na = End {
        xyz: va[ka].0,
        drop: a.drop + ka,
        inner: None,
        ..*a
    };
    let nb = End {
        xyz: vb[kb].0,
        drop: b.drop + kb,
        inner: None,
        ..*b
    };
    let dn = (nb.xyz[0] - na.xyz[0]).hypot(nb.xyz[1] - na.xyz[1]);
    // Curvature in metres: y'' = 2c / h². The arc with it bulges left (its tangent at the
    // first end turns left) where it is negative.
    let curvature = 2.0 * f[2] / (h * h);
    Some((na, nb, dn, -(0.5 * curvature * dn).clamp(-1.0, 1.0).asin()))
}

/// Spacing of the ground checks along a bridge, metres.
const CHECK_STEP_M: f64 = 0.5;

/// Horizontal radius and height band of the returns a ground check looks for, metres.
const CHECK_RADIUS_M: f64 = 0.15;
const CHECK_DZ_M: f64 = 0.1;

/// Least share of a bridge's ground checks that must find returns.
const CHECK_SHARE: f64 = 0.7;

/// Whether the arc from `a` to `b` (see [`on_arc`]) runs over measured ground (see the
/// module docs).
fn on_ground(
    input: &BendInput,
    grid: &PointGrid,
    a: [f64; 3],
    b: [f64; 3],
    alpha: f64,
    d: f64,
) -> bool {
    let n = (d / CHECK_STEP_M).ceil().max(1.0) as usize;
    let mut seen = 0usize;
    for k in 1..n {
        let q = on_arc(a, b, alpha, k as f64 / n as f64);
        let mut found = false;
        grid.for_each_within(input.x, input.y, q[0], q[1], CHECK_RADIUS_M, |i| {
            found |= usable(input, i) && (input.z[i] - q[2]).abs() <= CHECK_DZ_M;
        });
        seen += usize::from(found);
    }
    n < 2 || seen as f64 >= CHECK_SHARE * (n - 1) as f64
}

/// Joins the tracks that continue each other across a stretch with nothing tracked (see the
/// module docs), nearest pairs first. New vertices get ids from `next_id` on (ids at or past
/// the number of points are vertices between measured points, as the tracker's virtual
/// toes).
pub fn bridge_tracks(
    input: &BendInput,
    grid: &PointGrid,
    tracks: Vec<Track>,
    mut next_id: u32,
    params: &BendParams,
) -> Vec<Track> {
    if params.bridge_max_m <= 0.0 {
        return tracks;
    }
    let mut tracks: Vec<Option<Track>> = tracks.into_iter().map(Some).collect();
    loop {
        let ends: Vec<End> = tracks
            .iter()
            .enumerate()
            .filter_map(|(k, t)| t.as_ref().map(|t| (k, t)))
            .flat_map(|(k, t)| [end_of(t, k, false), end_of(t, k, true)])
            .flatten()
            .collect();
        let mut best: Option<(f64, f64, f64, End, End)> = None;
        for (i, a) in ends.iter().enumerate() {
            for b in ends.iter().skip(i + 1) {
                let (ta, tb) = (&tracks[a.track], &tracks[b.track]);
                let (Some(ta), Some(tb)) = (ta, tb) else {
                    continue;
                };
                if a.track == b.track || ta.side != tb.side {
                    continue;
                }
                let Some((d, alpha)) = fit(a, b, params) else {
                    continue;
                };
                if best.is_some_and(|(bd, _, _, _, _)| bd <= d) {
                    continue;
                }
                // The bridge runs between the ends before their hooks where those
                // continue each other too.
                let (ua, ub) = (a.unhooked(), b.unhooked());
                let (ua, ub, chord, bulge) = match fit(&ua, &ub, params) {
                    Some((du, alpha_u)) => (ua, ub, du, alpha_u),
                    None => (*a, *b, d, alpha),
                };
                // A bridge along a gently bending curb is laid on the line of both tracks.
                let (ua, ub, chord, bulge) = if bulge.abs() <= CURVE_FIT_MAX_TURN_DEG.to_radians() {
                    curb_line_fit(ta, &ua, tb, &ub).unwrap_or((ua, ub, chord, bulge))
                } else {
                    (ua, ub, chord, bulge)
                };
                // No other track may cross the bridge's chord.
                let (p, q) = ([a.xyz[0], a.xyz[1]], [b.xyz[0], b.xyz[1]]);
                let blocked = tracks.iter().flatten().any(|t| {
                    t.xyz
                        .windows(2)
                        .any(|w| crosses(p, q, [w[0][0], w[0][1]], [w[1][0], w[1][1]]))
                });
                if !blocked && on_ground(input, grid, ua.xyz, ub.xyz, bulge, chord) {
                    best = Some((d, bulge, chord, ua, ub));
                }
            }
        }
        let Some((_, alpha, d, a, b)) = best else {
            break;
        };
        let (Some(ta), Some(tb)) = (tracks[a.track].take(), tracks[b.track].take()) else {
            break;
        };
        // a's track ending at a, then the bridge, then b's track starting at b.
        let mut av: Vec<(u32, [f64; 3])> = ta.points.iter().copied().zip(ta.xyz).collect();
        let mut bv: Vec<(u32, [f64; 3])> = tb.points.iter().copied().zip(tb.xyz).collect();
        if !a.last {
            av.reverse();
        }
        if b.last {
            bv.reverse();
        }
        // Keep the order of the longer piece (the driving direction, as the tracker gives it).
        let flip = if av.len() >= bv.len() {
            !a.last
        } else {
            b.last
        };
        av.truncate(av.len() - a.drop);
        bv.drain(..b.drop);
        let steps = (d / BRIDGE_STEP_M).ceil().max(1.0) as usize;
        for k in 1..steps {
            av.push((
                next_id,
                on_arc(a.xyz, b.xyz, alpha, k as f64 / steps as f64),
            ));
            next_id = next_id.saturating_add(1);
        }
        av.extend(bv);
        if flip {
            av.reverse();
        }
        tracks[a.track] = Some(Track {
            points: av.iter().map(|v| v.0).collect(),
            xyz: av.iter().map(|v| v.1).collect(),
            side: ta.side,
        });
    }
    tracks.into_iter().flatten().collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::trajectory::Trajectory;
    use crate::model::Side;
    use crate::replay::PointStatus;

    fn line(from: f64, to: f64, y: impl Fn(f64) -> f64, id0: u32) -> Track {
        let mut xyz = Vec::new();
        let mut x = from;
        while x <= to + 1e-9 {
            xyz.push([x, y(x), 0.0]);
            x += 0.15;
        }
        Track {
            points: (id0..id0 + xyz.len() as u32).collect(),
            xyz,
            side: Side::Left,
        }
    }

    /// Flat ground at z = 0, a return every 0.1 m over x in [−15, 45], y in [−2, 8],
    /// except where `hole` says.
    struct Ground {
        x: Vec<f64>,
        y: Vec<f64>,
        z: Vec<f64>,
        t: Vec<f64>,
        rho: Vec<f32>,
        status: Vec<Option<PointStatus>>,
        scanline: Vec<u32>,
        traj: Trajectory,
    }

    fn ground(hole: impl Fn(f64, f64) -> bool) -> Ground {
        let mut g = Ground {
            x: Vec::new(),
            y: Vec::new(),
            z: Vec::new(),
            t: Vec::new(),
            rho: Vec::new(),
            status: Vec::new(),
            scanline: Vec::new(),
            traj: Trajectory::default(),
        };
        for i in 0..600 {
            for j in 0..100 {
                let (x, y) = (-15.0 + 0.1 * i as f64, -2.0 + 0.1 * j as f64);
                if hole(x, y) {
                    continue;
                }
                g.x.push(x);
                g.y.push(y);
                g.z.push(0.0);
                g.t.push(g.t.len() as f64);
                g.rho.push(0.0);
                g.status.push(Some(PointStatus::Kept));
                g.scanline.push(i);
            }
        }
        g
    }

    fn bridge(g: &Ground, tracks: Vec<Track>) -> Vec<Track> {
        let input = BendInput {
            x: &g.x,
            y: &g.y,
            z: &g.z,
            t: &g.t,
            rho_deg: &g.rho,
            status: &g.status,
            scanline: &g.scanline,
            candidates: &[],
            trajectory: &g.traj,
        };
        let grid = PointGrid::build(&g.x, &g.y, 0.1, |_| true);
        bridge_tracks(&input, &grid, tracks, 1_000_000, &BendParams::default())
    }

    #[test]
    fn a_cut_between_two_aligned_curbs_is_bridged_on_the_line() {
        let g = ground(|_, _| false);
        // A straight curb along y = 5 with 8 m missing, the later piece given first.
        let tracks = vec![line(18.0, 30.0, |_| 5.0, 100), line(0.0, 10.0, |_| 5.0, 0)];
        let out = bridge(&g, tracks);
        assert_eq!(out.len(), 1);
        let t = &out[0];
        assert_eq!(t.points.len(), t.xyz.len());
        assert!(t.xyz.iter().all(|q| (q[1] - 5.0).abs() < 1e-9));
        // In driving order (x growing), from 0 to 30 without a hole over 0.15 m.
        assert!(t
            .xyz
            .windows(2)
            .all(|w| w[1][0] > w[0][0] && w[1][0] - w[0][0] < 0.151));
        assert!(t.points.iter().any(|&id| id >= 1_000_000));
    }

    #[test]
    fn hooked_ends_are_bridged_on_the_curbs_line() {
        let g = ground(|_, _| false);
        // A straight curb along y = 5 with 8 m missing (a cut); over the last 0.4 m before
        // the gap each track slides 5 cm towards the road, as the kernel's peak does where
        // the curb lowers.
        let before = line(0.0, 10.0, |x| 5.0 - 0.125 * (x - 9.6).max(0.0), 0);
        let after = line(18.0, 30.0, |x| 5.0 - 0.125 * (18.4 - x).max(0.0), 100);
        let out = bridge(&g, vec![before, after]);
        assert_eq!(out.len(), 1);
        let t = &out[0];
        let bridged: Vec<_> = t
            .points
            .iter()
            .zip(&t.xyz)
            .filter(|(&id, _)| id >= 1_000_000)
            .collect();
        assert!(bridged.len() > 50);
        // The bridge continues the curb's line, and the hooks are left out.
        assert!(bridged.iter().all(|(_, q)| (q[1] - 5.0).abs() < 1e-6));
        assert!(t.xyz.iter().all(|q| q[1] > 4.995), "{:?}", t.xyz);
    }

    #[test]
    fn ends_that_drift_off_a_straight_curb_are_bridged_on_its_line() {
        let g = ground(|_, _| false);
        // A straight curb along y = 5 with 8 m missing (a flush cut); over the last 1.5 m
        // before the gap each track drifts 6 cm away from the road, with a vertex's
        // scatter of ±1 cm, as the kernel's peak does where the curb lowers slowly.
        let scatter = |x: f64| 0.01 * (7.3 * x).sin();
        let drift = |d: f64| 0.06 * (1.0 - d / 1.5).max(0.0);
        let before = line(0.0, 10.0, |x| 5.0 + scatter(x) + drift(10.0 - x), 0);
        let after = line(18.0, 30.0, |x| 5.0 + scatter(x) + drift(x - 18.0), 100);
        let out = bridge(&g, vec![before, after]);
        assert_eq!(out.len(), 1);
        let t = &out[0];
        let bridged: Vec<_> = t
            .points
            .iter()
            .zip(&t.xyz)
            .filter(|(&id, _)| id >= 1_000_000)
            .collect();
        assert!(bridged.len() > 50);
        // The bridge runs from vertices within the fit's drift limit of the curb's line,
        // and the farthest drifted vertices are left out.
        let worst = bridged
            .iter()
            .map(|(_, q)| (q[1] - 5.0).abs())
            .fold(0.0, f64::max);
        assert!(worst < 0.04, "{worst}");
        assert!(t.xyz.iter().all(|q| q[1] < 5.045), "{:?}", t.xyz);
    }

    /// Two tracks on an arc of radius `r` about (0, `r`), 8 m each with 8 m between them,
    /// bridged: the bridge's largest distance from the arc.
    fn arc_bridged_off_by(r: f64) -> f64 {
        let g = ground(|_, _| false);
        let arc = |x: f64| r - (r * r - x * x).sqrt();
        let tracks = vec![line(-12.0, -4.0, arc, 0), line(4.0, 12.0, arc, 100)];
        let out = bridge(&g, tracks);
        assert_eq!(out.len(), 1);
        out[0]
            .xyz
            .iter()
            .map(|q| (q[0].hypot(q[1] - r) - r).abs())
            .fold(0.0, f64::max)
    }

    #[test]
    fn a_gentle_bend_is_bridged_on_the_bend_of_both_tracks() {
        // A 150 m radius: the tangents over 2 m turn by under 4°.
        let worst = arc_bridged_off_by(150.0);
        assert!(worst < 0.005, "{worst}");
    }

    #[test]
    fn an_arc_is_bridged_on_the_arc() {
        let worst = arc_bridged_off_by(40.0);
        assert!(worst < 0.01, "{worst}");
    }

    #[test]
    fn offset_far_crossing_unseen_and_opposite_sides_are_not_bridged() {
        let g = ground(|_, _| false);
        // The later piece 0.4 m off the line (a bus bay or a car's flank, not this curb).
        let off = vec![line(0.0, 10.0, |_| 5.0, 0), line(16.0, 30.0, |_| 5.4, 100)];
        assert_eq!(bridge(&g, off).len(), 2);
        // Too far apart.
        let far = vec![line(0.0, 10.0, |_| 5.0, 0), line(30.0, 40.0, |_| 5.0, 100)];
        assert_eq!(bridge(&g, far).len(), 2);
        // Another track crosses the gap.
        let mut across = line(0.0, 3.0, |_| 0.0, 200);
        across
            .xyz
            .iter_mut()
            .for_each(|q| *q = [14.0, q[0] + 3.53, 0.0]);
        let crossed = vec![
            line(0.0, 10.0, |_| 5.0, 0),
            line(18.0, 30.0, |_| 5.0, 100),
            across,
        ];
        assert_eq!(bridge(&g, crossed).len(), 3);
        // The other side of the road.
        let mut right = line(18.0, 30.0, |_| 5.0, 100);
        right.side = Side::Right;
        let sides = vec![line(0.0, 10.0, |_| 5.0, 0), right];
        assert_eq!(bridge(&g, sides).len(), 2);
        // No returns along the gap (an area the scanner did not see).
        let unseen = ground(|x, _| (11.0..17.0).contains(&x));
        let tracks = vec![line(0.0, 10.0, |_| 5.0, 0), line(18.0, 30.0, |_| 5.0, 100)];
        assert_eq!(bridge(&unseen, tracks).len(), 2);
    }
}
