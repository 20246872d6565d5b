//! The trajectory as a route in the horizontal plane: arc length at a time (for cutting
//! the seed candidates into intervals of L_s, §2.6), the driving direction at a time, and
//! the nearest route point to a position (the post-filter of §2.7, categories).

use super::grid::PointGrid;
use crate::io::trajectory::Trajectory;
use std::cmp::Ordering;

/// Horizontal route of the trajectory with cumulative arc length.
pub struct Route {
    t: Vec<f64>,
    x: Vec<f64>,
    y: Vec<f64>,
    s: Vec<f64>,
    heading_deg: Vec<f64>,
    /// Whether every sample's position is finite.
    finite: bool,
    /// Decimated vertices (indices into the columns above) for nearest-point queries.
    grid: PointGrid,
}

/// Spacing of the vertices kept for nearest-point queries, metres.
const DECIMATE_M: f64 = 0.5;

impl Route {
    /// Builds the route from the trajectory samples.
    pub fn new(traj: &Trajectory) -> Self {
        let n = traj.samples.len();
        let mut r = Route {
            t: Vec::with_capacity(n),
            x: Vec::with_capacity(n),
            y: Vec::with_capacity(n),
            s: Vec::with_capacity(n),
            heading_deg: Vec::with_capacity(n),
            finite: true,
            grid: PointGrid::build(&[], &[], 1.0, |_| true),
        };
        let mut s = 0.0;
        for (k, p) in traj.samples.iter().enumerate() {
            if k > 0 {
                s += (p.x - r.x[k - 1]).hypot(p.y - r.y[k - 1]);
            }
            r.t.push(p.t);
            r.x.push(p.x);
            r.y.push(p.y);
            r.s.push(s);
            r.heading_deg.push(p.heading_deg);
            r.finite &= p.x.is_finite() && p.y.is_finite();
        }
        // Keep a vertex every DECIMATE_M (and the last one) for the nearest-point index.
        let mut keep = vec![false; n];
        let mut last_s = f64::NEG_INFINITY;
        for (k, kept) in keep.iter_mut().enumerate() {
            if r.s[k] - last_s >= DECIMATE_M || k + 1 == n {
                *kept = true;
                last_s = r.s[k];
            }
        }
        r.grid = PointGrid::build(&r.x, &r.y, 5.0, |k| keep[k]);
        r
    }

    fn bracket(&self, t: f64) -> Option<(usize, f64)> {
        let n = self.t.len();
        if n == 0 || !t.is_finite() {
            return None;
        }
        if n == 1 {
            return Some((0, 0.0));
        }
        Some(self.bracket_after(t, self.t.partition_point(|&u| u <= t)))
    }

    /// The bracket of a finite time `t` on a route of two or more samples, `after` of
    /// which lie at or before it.
    fn bracket_after(&self, t: f64, after: usize) -> (usize, f64) {
        let k = after.clamp(1, self.t.len() - 1);
        let (a, b) = (self.t[k - 1], self.t[k]);
        let w = if b > a {
            ((t - a) / (b - a)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (k - 1, w)
    }

    /// Arc length along the route at time `t`, metres (clamped to the covered range).
    pub fn arc_at(&self, t: f64) -> Option<f64> {
        let (k, w) = self.bracket(t)?;
        Some(self.arc_in(k, w))
    }

    /// [`arc_at`](Self::arc_at) for times that seldom go back from one call to the next:
    /// `cursor` (0 at first) keeps how many samples lay at or before the last time, and
    /// the search walks on from there instead of bisecting every sample.
    pub fn arc_at_from(&self, t: f64, cursor: &mut usize) -> Option<f64> {
        let n = self.t.len();
        if n < 2 || !t.is_finite() {
            return self.arc_at(t);
        }
        let mut after = (*cursor).min(n);
        if after > 0 && self.t[after - 1] > t {
            after = self.t.partition_point(|&u| u <= t);
        }
        while after < n && self.t[after] <= t {
            after += 1;
        }
        *cursor = after;
        let (k, w) = self.bracket_after(t, after);
        Some(self.arc_in(k, w))
    }

    /// [`arc_at`](Self::arc_at) of a time `t` at or after sample `k`'s time and before
    /// sample `k + 1`'s (at or after the last sample's when `k` is the last; before the
    /// first sample's too when `k` is 0), for a caller that walks the samples itself.
    pub fn arc_at_sample(&self, t: f64, k: usize) -> Option<f64> {
        if self.t.len() < 2 || !t.is_finite() {
            return self.arc_at(t);
        }
        let (j, w) = self.bracket_after(t, k + 1);
        Some(self.arc_in(j, w))
    }

    /// The arc length a fraction `w` of the way from sample `k` to the next.
    fn arc_in(&self, k: usize, w: f64) -> f64 {
        let next = (k + 1).min(self.s.len() - 1);
        self.s[k] + (self.s[next] - self.s[k]) * w
    }

    /// Horizontal position and forward unit vector where the route's arc length is `s`
    /// metres (clamped to the covered range).
    pub fn pose_at_arc(&self, s: f64) -> Option<([f64; 2], [f64; 2])> {
        let n = self.s.len();
        if n == 0 || !s.is_finite() {
            return None;
        }
        let k = self
            .s
            .partition_point(|&u| u <= s)
            .clamp(1, n.max(2) - 1)
            .min(n - 1);
        let j = k.saturating_sub(1);
        let (a, b) = (self.s[j], self.s[k]);
        let w = if b > a {
            ((s - a) / (b - a)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let p = [
            self.x[j] + (self.x[k] - self.x[j]) * w,
            self.y[j] + (self.y[k] - self.y[j]) * w,
        ];
        let t = self.t[j] + (self.t[k] - self.t[j]) * w;
        Some((p, self.forward_at(t)?))
    }

    /// Horizontal forward unit vector at time `t` (from the heading, docs/spec.md §2).
    pub fn forward_at(&self, t: f64) -> Option<[f64; 2]> {
        let (k, w) = self.bracket(t)?;
        let next = (k + 1).min(self.s.len() - 1);
        let h0 = self.heading_deg[k];
        let mut dh = (self.heading_deg[next] - h0) % 360.0;
        if dh > 180.0 {
            dh -= 360.0;
        } else if dh < -180.0 {
            dh += 360.0;
        }
        let h = (h0 + dh * w).to_radians();
        Some([h.sin(), h.cos()])
    }

    /// Arc length of the nearest point of the route to `(px, py)`, metres, or `None` for
    /// an empty route.
    pub fn station_near(&self, px: f64, py: f64) -> Option<f64> {
        let (q, _, on) = self.nearest_on(px, py)?;
        // The nearest point lies on a segment of the original samples: find it by position.
        let k = self.segment_near(q, on)?;
        let next = (k + 1).min(self.s.len() - 1);
        let l = (self.x[next] - self.x[k]).hypot(self.y[next] - self.y[k]);
        let u = if l > 0.0 {
            ((q[0] - self.x[k]).hypot(q[1] - self.y[k]) / l).clamp(0.0, 1.0)
        } else {
            0.0
        };
        Some(self.s[k] + u * (self.s[next] - self.s[k]))
    }

    /// The route segment (index of its first sample) passing closest to `q`, searched among
    /// the samples within 4 m (of arc) of the nearest kept vertex, the first on ties.
    ///
    /// Segment `hint`, where one is known to lie near `q`, bounds the search: a segment
    /// whose box lies farther from `q` along x or y than the hint's offset (the sum of its
    /// components, plus [`SEGMENT_SLACK`] of the coordinates, far above their rounding)
    /// is neither nearer than the hint nor tied with it, so it is passed over without its
    /// offset; the segment found is the one the whole search finds.
    fn segment_near(&self, q: [f64; 2], hint: usize) -> Option<usize> {
        let mut best: Option<([f64; 2], usize)> = None;
        let mut r = 2.0 * DECIMATE_M;
        while best.is_none() && r < 1e7 {
            self.grid
                .for_each_within(&self.x, &self.y, q[0], q[1], r, |k| {
                    let d = [self.x[k] - q[0], self.y[k] - q[1]];
                    if best.is_none_or(|(bd, bk)| nearer_first(d, k, bd, bk)) {
                        best = Some((d, k));
                    }
                });
            r *= 4.0;
        }
        let (_, k0) = best?;
        let s0 = self.s[k0];
        let lo = self.s.partition_point(|&s| s < s0 - 4.0).saturating_sub(1);
        let hi = self
            .s
            .partition_point(|&s| s <= s0 + 4.0)
            .min(self.s.len() - 1);
        let offset = |k: usize| {
            let e = (k + 1).min(self.s.len() - 1);
            let (ax, ay, dx, dy) = (
                self.x[k],
                self.y[k],
                self.x[e] - self.x[k],
                self.y[e] - self.y[k],
            );
            let l2 = dx * dx + dy * dy;
            let u = if l2 > 0.0 {
                (((q[0] - ax) * dx + (q[1] - ay) * dy) / l2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            [ax + u * dx - q[0], ay + u * dy - q[1]]
        };
        // Beyond `bound` along an axis no segment can win (no bound unless the route and
        // the hint's offset are finite: a NaN offset is kept where it comes first).
        let bound = if self.finite && (lo..=hi).contains(&hint) {
            let d = offset(hint);
            let b = d[0].abs() + d[1].abs() + SEGMENT_SLACK * (q[0].abs() + q[1].abs() + 1.0);
            if b.is_finite() {
                b
            } else {
                f64::INFINITY
            }
        } else {
            f64::INFINITY
        };
        let mut out: Option<([f64; 2], usize)> = None;
        for k in lo..=hi {
            let e = (k + 1).min(self.s.len() - 1);
            let (xa, xb, ya, yb) = (self.x[k], self.x[e], self.y[k], self.y[e]);
            let (x_lo, x_hi) = if xa < xb { (xa, xb) } else { (xb, xa) };
            let (y_lo, y_hi) = if ya < yb { (ya, yb) } else { (yb, ya) };
            if x_lo - q[0] > bound
                || q[0] - x_hi > bound
                || y_lo - q[1] > bound
                || q[1] - y_hi > bound
            {
                continue;
            }
            let d = offset(k);
            if out.is_none_or(|(bd, _)| shorter(d, bd) == Some(Ordering::Less)) {
                out = Some((d, k));
            }
        }
        out.map(|o| o.1)
    }

    /// Arc length of the route's last sample, metres.
    pub fn length_m(&self) -> f64 {
        self.s.last().copied().unwrap_or(0.0)
    }

    /// The nearest point of the route polyline to `(px, py)` and the forward unit vector
    /// there, or `None` for an empty route.
    pub fn nearest(&self, px: f64, py: f64) -> Option<([f64; 2], [f64; 2])> {
        self.nearest_on(px, py).map(|(q, fwd, _)| (q, fwd))
    }

    /// [`Route::nearest`], with the index of the sample that begins the segment the point
    /// lies on.
    fn nearest_on(&self, px: f64, py: f64) -> Option<([f64; 2], [f64; 2], usize)> {
        if self.t.is_empty() {
            return None;
        }
        // Nearest kept vertex: widen the disc until it holds one.
        let mut best: Option<([f64; 2], usize)> = None;
        let mut r = 10.0;
        while best.is_none() && r < 1e7 {
            self.grid.for_each_within(&self.x, &self.y, px, py, r, |k| {
                let d = [self.x[k] - px, self.y[k] - py];
                if best.is_none_or(|(bd, bk)| nearer_first(d, k, bd, bk)) {
                    best = Some((d, k));
                }
            });
            r *= 4.0;
        }
        let (_, k0) = best?;
        // Refine on the original segments around it (±DECIMATE_M worth of samples).
        let s0 = self.s[k0];
        let lo = self
            .s
            .partition_point(|&s| s < s0 - 2.0 * DECIMATE_M)
            .saturating_sub(1);
        let hi = self
            .s
            .partition_point(|&s| s <= s0 + 2.0 * DECIMATE_M)
            .min(self.s.len() - 1);
        let mut best_p = ([self.x[k0], self.y[k0]], [f64::INFINITY, 0.0], k0);
        for k in lo..=hi {
            let seg_end = (k + 1).min(hi);
            let (ax, ay) = (self.x[k], self.y[k]);
            let (bx, by) = (self.x[seg_end], self.y[seg_end]);
            let (dx, dy) = (bx - ax, by - ay);
            let l2 = dx * dx + dy * dy;
            let u = if l2 > 0.0 {
                (((px - ax) * dx + (py - ay) * dy) / l2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let q = [ax + u * dx, ay + u * dy];
            let d = [q[0] - px, q[1] - py];
            if shorter(d, best_p.1) == Some(Ordering::Less) {
                best_p = (q, d, k);
            }
        }
        let h = self.heading_deg[best_p.2].to_radians();
        Some((best_p.0, [h.sin(), h.cos()], best_p.2))
    }
}

/// Margin of [`Route::segment_near`]'s bound, relative to the coordinates' magnitude:
/// far above their rounding.
const SEGMENT_SLACK: f64 = 1e-9;

/// Squared lengths closer than this (relative) are compared by `hypot` itself.
const SQUARED_TIE: f64 = 1e-9;

/// Squared lengths below this are compared by `hypot` itself (squares of smaller
/// components lose their relative precision).
const SQUARED_TINY: f64 = 1e-250;

/// Compares the lengths of two horizontal offsets exactly as comparing their `hypot`s
/// would (`None` where one is NaN), without calling `hypot` unless the two are within
/// `SQUARED_TIE` of each other.
///
/// `a² + b²` in floating point is within a few ulps of the true square (for squares
/// above `SQUARED_TINY`, finite) and `hypot` within an ulp or two of the true length: two
/// squares `SQUARED_TIE` apart have lengths that far apart, beyond both errors, so their
/// `hypot`s order as the squares do. Nearer ties, infinities and NaNs go to `hypot`, so
/// the nearest point and its ties (broken by index) are those of a `hypot` comparison.
fn shorter(a: [f64; 2], b: [f64; 2]) -> Option<Ordering> {
    let (sa, sb) = (a[0] * a[0] + a[1] * a[1], b[0] * b[0] + b[1] * b[1]);
    if sa.is_finite() && sb.is_finite() && sa.max(sb) >= SQUARED_TINY {
        if sa < sb * (1.0 - SQUARED_TIE) {
            return Some(Ordering::Less);
        }
        if sb < sa * (1.0 - SQUARED_TIE) {
            return Some(Ordering::Greater);
        }
    }
    a[0].hypot(a[1]).partial_cmp(&b[0].hypot(b[1]))
}

/// True when offset `d` of vertex `k` is nearer than offset `bd` of vertex `bk`, ties
/// going to the lower index.
fn nearer_first(d: [f64; 2], k: usize, bd: [f64; 2], bk: usize) -> bool {
    match shorter(d, bd) {
        Some(Ordering::Less) => true,
        Some(Ordering::Equal) => k < bk,
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::trajectory::Pose;

    fn east_route() -> Route {
        // Driving east (heading 90°) at 10 m/s from (1000, 2000), 11 samples.
        let samples = (0..=10)
            .map(|k| Pose {
                t: 100.0 + k as f64,
                x: 1000.0 + 10.0 * k as f64,
                y: 2000.0,
                z: 2.0,
                roll_deg: 0.0,
                pitch_deg: 0.0,
                heading_deg: 90.0,
            })
            .collect();
        Route::new(&Trajectory { samples })
    }

    #[test]
    fn arc_length_and_direction_at_a_time() {
        let r = east_route();
        assert!((r.arc_at(103.25).unwrap() - 32.5).abs() < 1e-9);
        assert_eq!(r.arc_at(50.0), Some(0.0));
        let f = r.forward_at(104.0).unwrap();
        assert!((f[0] - 1.0).abs() < 1e-12 && f[1].abs() < 1e-12);
    }

    #[test]
    fn arc_from_a_cursor_is_the_arc_at_the_time() {
        let r = east_route();
        // On samples, between them, before and after the route, going back, and NaN.
        let on_and_between = [99.0, 100.0, 100.5, 101.0, 101.0, 104.7, 103.2, 103.2];
        let past_and_back = [109.99, 110.0, 111.0, 100.1, f64::NAN, 105.5];
        let mut cursor = 0;
        for t in on_and_between.into_iter().chain(past_and_back) {
            let want = r.arc_at(t).map(f64::to_bits);
            assert_eq!(r.arc_at_from(t, &mut cursor).map(f64::to_bits), want, "{t}");
        }
        assert_eq!(r.arc_at_from(103.25, &mut cursor), Some(32.5));
    }

    #[test]
    fn arc_at_a_walked_sample_is_the_arc_at_the_time() {
        let r = east_route();
        let single = Route::new(&Trajectory {
            samples: vec![Pose {
                t: 100.0,
                x: 0.0,
                y: 0.0,
                z: 0.0,
                roll_deg: 0.0,
                pitch_deg: 0.0,
                heading_deg: 0.0,
            }],
        });
        // Before the first sample, on samples, between them, on and after the last, NaN.
        for t in [
            99.0,
            100.0,
            100.5,
            101.0,
            104.7,
            109.99,
            110.0,
            111.0,
            f64::NAN,
        ] {
            // The last sample at or before `t`, 0 when there is none.
            let k = r.t.iter().rposition(|&u| u <= t).unwrap_or(0);
            let want = r.arc_at(t).map(f64::to_bits);
            assert_eq!(r.arc_at_sample(t, k).map(f64::to_bits), want, "{t}");
            assert_eq!(single.arc_at_sample(t, 0), single.arc_at(t), "{t}");
        }
        assert_eq!(r.arc_at_sample(103.25, 3), Some(32.5));
    }

    #[test]
    fn shorter_orders_as_hypot_does() {
        let hyp = |a: [f64; 2], b: [f64; 2]| a[0].hypot(a[1]).partial_cmp(&b[0].hypot(b[1]));
        let up = |v: f64, k: u64| f64::from_bits(v.to_bits() + k);
        let mut seed = 7u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 20.0 - 10.0
        };
        for _ in 0..20_000 {
            let a = [next(), next()];
            // The same length turned, neighbouring ulps, and an unrelated offset.
            let r = a[0].hypot(a[1]);
            let cands = [
                [a[1], a[0]],
                [-a[0], a[1]],
                [up(a[0].abs(), 1), a[1]],
                [a[0], up(a[1].abs(), 3)],
                [r, 0.0],
                [0.0, up(r, 1)],
                [next(), next()],
            ];
            for b in cands {
                assert_eq!(shorter(a, b), hyp(a, b), "{a:?} {b:?}");
                assert_eq!(shorter(b, a), hyp(b, a), "{b:?} {a:?}");
            }
        }
        let odd = [
            [f64::NAN, 1.0],
            [f64::INFINITY, 0.0],
            [1e200, 1e200],
            [1e-200, 0.0],
            [0.0, -0.0],
        ];
        for a in odd {
            for b in odd {
                assert_eq!(shorter(a, b), hyp(a, b), "{a:?} {b:?}");
            }
        }
    }

    #[test]
    fn nearest_point_is_the_foot_of_the_perpendicular() {
        let r = east_route();
        let (q, f) = r.nearest(1043.3, 2005.0).unwrap();
        assert!((q[0] - 1043.3).abs() < 1e-9 && (q[1] - 2000.0).abs() < 1e-9);
        assert!((f[0] - 1.0).abs() < 1e-12);
        // Beyond the end: the last sample.
        let (q, _) = r.nearest(1200.0, 1990.0).unwrap();
        assert!((q[0] - 1100.0).abs() < 1e-9 && (q[1] - 2000.0).abs() < 1e-9);
    }
}
