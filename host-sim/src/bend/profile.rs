//! The curb toe on a virtual profile across the direction of travel, gathered from the
//! points of several scanlines, where the per-scanline bend angle sees no toe.

use super::grid::PointGrid;
use super::params::BendParams;
use super::BendInput;
use crate::replay::PointStatus;

/// Points a virtual profile may use: kept by the core, with or without a bend angle.
pub(super) fn usable(input: &BendInput, i: usize) -> bool {
    matches!(
        input.status[i],
        Some(PointStatus::Kept | PointStatus::NoNeighbour)
    )
}

/// A curb toe found on a virtual profile.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProfileToe {
    /// Toe position: horizontal on the profile line, height of the road beside it.
    pub xyz: [f64; 3],
    /// Height step from the road to the curb top, metres.
    pub step_m: f64,
}

/// A *virtual profile*: the points (of any scanline) within `half_l` of the line through
/// `centre` across the horizontal unit direction `along`, taken as one cross-section with
/// `across` running from the road (negative) to the curb side (positive, `up` = +1 for the
/// left of `along`, −1 for the right). It carries the points, their grid and the
/// parameters with it, so that each query on a profile ([`Profile::toe`],
/// [`Profile::cut_toe`], [`Profile::shadow_shift`]) takes the profile alone.
#[derive(Clone, Copy)]
pub struct Profile<'a> {
    pub input: &'a BendInput<'a>,
    pub grid: &'a PointGrid,
    pub params: &'a BendParams,
    pub centre: [f64; 3],
    pub along: [f64; 2],
    pub up: f64,
    pub half_l: f64,
}

impl Profile<'_> {
    /// The same profile, `half_l` long either side of its centre.
    pub fn with_half_l(self, half_l: f64) -> Self {
        Self { half_l, ..self }
    }

    /// The horizontal unit normal from the road towards the curb side.
    fn across(&self) -> [f64; 2] {
        let (along, up) = (self.along, self.up);
        [-along[1] * up, along[0] * up]
    }

    /// The point in plan `a` along the profile and `c` across it from its centre.
    pub(super) fn plan_at(&self, a: f64, c: f64) -> [f64; 2] {
        let (centre, along, n) = (self.centre, self.along, self.across());
        [
            centre[0] + a * along[0] + c * n[0],
            centre[1] + a * along[1] + c * n[1],
        ]
    }

    /// [`Profile::toe`], else the toe on the profile twice as long: far from the scanner
    /// the points are sparse along the scanlines, and the short profile holds too few.
    pub fn toe_or_longer(&self) -> Option<ProfileToe> {
        self.toe()
            .or_else(|| self.with_half_l(2.0 * self.half_l).toe())
    }

    /// Finds the curb toe on a virtual profile ([`Profile`]).
    ///
    /// The per-scanline bend angle (Honma et al. §2.3) sees a curb only where the scanline
    /// crosses it; where a curb turns to run along the scanlines (the side streets of
    /// intersections, the far part of corner arcs) every scanline runs beside the toe and ρ
    /// stays flat, while the height step is still there *between* scanlines. The profile
    /// gathers it from several scanlines: the points sorted by `across` are split in two at
    /// the place that minimises the squared deviation from two levels (a least-squares step
    /// fit), and the toe is half-way between the last point of the low part and the first of
    /// the high part. Each part, without the 40 mm next to the toe (the face), is then fitted
    /// by a line, and the toe is accepted only as a curb: a step of at least
    /// `profile_min_step_m` (and under the search half-height) between the two lines at the
    /// toe, both parts ground-like (slopes under `profile_max_slope`, so a curb cut's ramp is
    /// no step; a road part falling to the toe under `profile_max_road_fall`), the lines'
    /// RMS under a quarter of the step, ground within 0.15 m on both sides of the toe, and
    /// the toe within `profile_half_width_m` − 0.15 m of the centre.
    pub fn toe(&self) -> Option<ProfileToe> {
        self.split().map(|s| s.toe)
    }
}

/// The toe of [`Profile::toe`] with the offsets across the profile it was split at.
#[derive(Clone, Copy, Debug)]
struct Split {
    toe: ProfileToe,
    /// The toe's offset across, half-way between `last_low` and `first_high`.
    at: f64,
    /// Offset of the last road point before the toe.
    last_low: f64,
    /// Offset of the first curb point after it.
    first_high: f64,
}

/// Narrowest gap between the last road and the first curb point of a profile that can be
/// the curb's shadow rather than the face, metres.
const SHADOW_MIN_GAP_M: f64 = 0.1;

impl Profile<'_> {
    /// How far across, towards the curb, a toe that [`Profile::toe`] finds on the profile
    /// lies from where it puts it, with that toe: half of the way from the
    /// middle of the gap between the road and the curb points to the first curb point where
    /// that gap is the curb's shadow ([`Profile::in_shadow`]), else 0.
    ///
    /// Across a shadow the returns beside the toe are the curb's (the scanner looks at the
    /// curb from behind and sees its top up to the arris), while the road before it is
    /// hidden for the shadow's length, so the middle of the gap lies on the road. The toe
    /// lies between the middle and the first curb return: the arris lies a face's width
    /// behind the toe, and the first return up to a point spacing behind the arris.
    pub fn shadow_shift(&self) -> Option<(ProfileToe, f64)> {
        let s = self.split()?;
        let shadow = s.first_high - s.last_low >= SHADOW_MIN_GAP_M
            && self.in_shadow(s.at, &[s.last_low, s.first_high]);
        let shift = if shadow {
            0.5 * (s.first_high - s.at)
        } else {
            0.0
        };
        Some((s.toe, shift))
    }

    /// Whether the scanner stood on the curb's side of the toe (offset `toe` across) when it
    /// measured the profile's points at the offsets `at`: there the raised curb hides the road
    /// just past the toe (the curb's shadow). `false` where the trajectory does not cover a
    /// point's time.
    fn in_shadow(&self, toe: f64, at: &[f64]) -> bool {
        let (input, centre) = (self.input, self.centre);
        let n = self.across();
        let (mut any, mut all) = (false, true);
        self.for_each(|i, c, _| {
            if at.contains(&c) {
                any = true;
                all &= input
                    .trajectory
                    .pose_at(input.t[i])
                    .is_some_and(|p| (p.x - centre[0]) * n[0] + (p.y - centre[1]) * n[1] > toe);
            }
        });
        any && all
    }

    /// [`Profile::toe`], and where it finds none, the toe on the profile without the points
    /// that lie on the curb's face (second), gathered once.
    ///
    /// Far from the scanner the returns lie a decimetre or two apart across, and where one
    /// of them falls on the face (or the chamfer at its top) half-way up the step, it
    /// belongs to neither level: joined to the road it tilts the road's line, joined to the
    /// curb it tilts the top's or shrinks the step, and [`Profile::toe`] sees no curb on a
    /// profile that shows one. Here the profile is split in two levels as there; the points
    /// within [`SPLIT_NEAR_M`] of that split whose heights lie more than a quarter of the step
    /// (between the two parts' median heights) from both levels are left out, and
    /// [`Profile::toe`]'s search is made on the rest with all of its tests. A ramp (a curb
    /// cut's) leaves more than [`SPLIT_NEAR_M`] of points between the levels and still
    /// fails them. The second is `None` where no point lies on the face (the search would
    /// be [`Profile::toe`]'s).
    pub fn toe_or_past_face(&self) -> (Option<ProfileToe>, Option<ProfileToe>) {
        let prof = self.gather();
        match self.split_points(&prof) {
            Some(s) => (Some(s.toe), None),
            None => (None, self.past_face(&prof)),
        }
    }

    /// [`Profile::toe_or_past_face`]'s second toe on the profile's points `prof`.
    fn past_face(&self, prof: &[(f64, f64, f64)]) -> Option<ProfileToe> {
        if prof.len() < 2 * SPLIT_MIN_SIDE {
            return None;
        }
        let k = level_split(prof, &Sums::new(prof))?;
        let toe = 0.5 * (prof[k - 1].0 + prof[k].0);
        let mut z: Vec<f64> = prof.iter().map(|p| p.1).collect();
        let (low, high) = z.split_at_mut(k);
        let (zl, zh) = (select_median(low)?, select_median(high)?);
        if zh - zl < self.params.profile_min_step_m {
            return None;
        }
        let q = 0.25 * (zh - zl);
        let on_face =
            |p: &(f64, f64, f64)| (p.0 - toe).abs() <= SPLIT_NEAR_M && p.1 > zl + q && p.1 < zh - q;
        if !prof.iter().any(on_face) {
            return None;
        }
        let rest: Vec<(f64, f64, f64)> = prof.iter().filter(|p| !on_face(p)).copied().collect();
        self.split_points(&rest).map(|s| s.toe)
    }

    /// [`Profile::toe`]'s search, with the offsets it split the profile at.
    fn split(&self) -> Option<Split> {
        self.split_points(&self.gather())
    }

    /// [`Profile::split`] on the points `prof` (across, z, along), sorted by `across`.
    fn split_points(&self, prof: &[(f64, f64, f64)]) -> Option<Split> {
        let params = self.params;
        let half_w = params.profile_half_width_m;
        const MIN_SIDE: usize = SPLIT_MIN_SIDE;
        let m = prof.len();
        if m < 2 * MIN_SIDE {
            return None;
        }
        let sums = Sums::new(prof);
        let line = |lo: usize, hi: usize| sums.line(lo, hi);
        let k = level_split(prof, &sums)?;
        let toe = 0.5 * (prof[k - 1].0 + prof[k].0);
        const NEAR_M: f64 = SPLIT_NEAR_M;
        if prof[k].0 - prof[k - 1].0 > 2.0 * NEAR_M || toe.abs() > half_w - NEAR_M {
            return None;
        }
        // The two parts without the face (FACE_M either side of the toe), each fitted by a
        // line (road cross slope, sidewalk fall).
        const FACE_M: f64 = 0.04;
        let lo = prof.partition_point(|p| p.0 < toe - FACE_M);
        let hi = prof.partition_point(|p| p.0 <= toe + FACE_M);
        if lo < MIN_SIDE || m - hi < MIN_SIDE {
            return None;
        }
        if prof[lo - 1].0 < toe - NEAR_M || prof[hi].0 > toe + NEAR_M {
            return None; // no ground seen right beside the toe
        }
        let (la, lb, le) = line(0, lo);
        let (ha, hb, he) = line(hi, m);
        let step = (ha + hb * toe) - (la + lb * toe);
        let rms = ((le + he) / (lo + m - hi) as f64).sqrt();
        // Both parts must be ground, not a ramp or a car's flank; the road may fall to the
        // toe more steeply (a gutter, a grade across a side street's curb).
        let max_slope = params.profile_max_slope;
        if lb > max_slope || -lb > params.profile_max_road_fall || hb.abs() > max_slope {
            return None;
        }
        if step < params.profile_min_step_m || step > params.search_half_height_m {
            return None;
        }
        if rms > 0.25 * step {
            return None;
        }
        // The road height at the toe: the low points within NEAR_M of it.
        let near_low: Vec<f64> = prof[..k]
            .iter()
            .filter(|p| toe - p.0 <= NEAR_M)
            .map(|p| p.1)
            .collect();
        let z = near_low.iter().sum::<f64>() / near_low.len().max(1) as f64;
        // Along the profile the toe sits among the points beside it, not at the centre: where
        // the scanned area ends, the centre lies past the last scanline.
        let near: Vec<f64> = prof
            .iter()
            .filter(|p| (p.0 - toe).abs() <= NEAR_M)
            .map(|p| p.2)
            .collect();
        let a = near.iter().sum::<f64>() / near.len().max(1) as f64;
        Some(Split {
            toe: ProfileToe {
                xyz: {
                    let [x, y] = self.plan_at(a, toe);
                    [x, y, z]
                },
                step_m: step,
            },
            at: toe,
            last_low: prof[k - 1].0,
            first_high: prof[k].0,
        })
    }
}

/// The median of `v` as [`super::median`] gives it, by selection rather than a sort (`v` is
/// reordered); `None` when empty.
fn select_median(v: &mut [f64]) -> Option<f64> {
    let (n, m) = (v.len(), v.len() / 2);
    if n == 0 {
        return None;
    }
    let (lower, mid, _) = v.select_nth_unstable_by(m, |a, b| a.total_cmp(b));
    let mid = *mid;
    Some(if n % 2 == 1 {
        mid
    } else {
        let below = lower.iter().copied().max_by(|a, b| a.total_cmp(b))?;
        0.5 * (below + mid)
    })
}

/// Fewest points on each side of [`Profile::toe`]'s split.
const SPLIT_MIN_SIDE: usize = 4;

/// Farthest from [`Profile::toe`]'s toe that the nearest road and curb points may lie,
/// metres (ground seen right beside the toe).
const SPLIT_NEAR_M: f64 = 0.15;

/// The best split k of `prof` (sorted by `across`; `sums` its running sums) into two levels,
/// `prof[..k]` the road and `prof[k..]` the curb, each of at least [`SPLIT_MIN_SIDE`] points,
/// by the least squared deviation from the two levels; `None` where there is none. Points on
/// the curb face go to the nearer level, so the split falls at the face's middle.
fn level_split(prof: &[(f64, f64, f64)], sums: &Sums) -> Option<usize> {
    let m = prof.len();
    if m < 2 * SPLIT_MIN_SIDE {
        return None;
    }
    let acc = &sums.acc;
    // Σ(z − mean)² over prof[lo..hi].
    let level_sse = |lo: usize, hi: usize| {
        let (n, sz, szz) = (
            (hi - lo) as f64,
            acc[hi][3] - acc[lo][3],
            acc[hi][5] - acc[lo][5],
        );
        (szz - sz * sz / n).max(0.0)
    };
    let mut best: Option<(f64, usize)> = None;
    for k in SPLIT_MIN_SIDE..=m - SPLIT_MIN_SIDE {
        if prof[k].0 - prof[k - 1].0 <= 0.0 {
            continue; // a split must fall between two distinct positions
        }
        let e = level_sse(0, k) + level_sse(k, m);
        if best.is_none_or(|(be, _)| e < be) {
            best = Some((e, k));
        }
    }
    best.map(|(_, k)| k)
}

/// A thread's buffers for [`Profile::gather`]: the points as the grid hands them over and the sort's
/// keys and buckets, kept from one profile to the next (a section gathers thousands of
/// profiles of a few thousand points each; growing fresh vectors for each cost more than
/// sorting them).
#[derive(Default)]
struct Scratch {
    prof: Vec<(f64, f64, f64)>,
    keys: Vec<(u64, u64, u32)>,
    starts: Vec<u32>,
}

std::thread_local! {
    static SCRATCH: std::cell::RefCell<Scratch> = std::cell::RefCell::new(Scratch::default());
}

impl Profile<'_> {
    /// The profile's points as (across, z, along), sorted by `across`, then height.
    pub(super) fn gather(&self) -> Vec<(f64, f64, f64)> {
        let input = self.input;
        SCRATCH.with_borrow_mut(|s| {
            s.prof.clear();
            self.for_each(|i, c, a| s.prof.push((c, input.z[i], a)));
            sort_across(&s.prof, &mut s.keys, &mut s.starts)
        })
    }

    /// Calls `f(i, across, along)` for every usable point `i` of the profile: within
    /// `profile_half_width_m` across and `half_l` along of `centre`, and within the search
    /// half-height of its height.
    pub(super) fn for_each(&self, mut f: impl FnMut(usize, f64, f64)) {
        let (input, params, centre, along, half_l) = (
            self.input,
            self.params,
            self.centre,
            self.along,
            self.half_l,
        );
        let half_w = params.profile_half_width_m;
        let n = self.across();
        self.grid.for_each_in_rect(
            input.x,
            input.y,
            [centre[0], centre[1]],
            along,
            n,
            half_l,
            half_w,
            half_w.hypot(half_l),
            |i, c, a| {
                if !usable(input, i) || (input.z[i] - centre[2]).abs() > params.search_half_height_m
                {
                    return;
                }
                f(i, c, a);
            },
        );
    }
}

/// `prof` sorted by `across`, then height, by `total_cmp`, points equal in both kept in
/// the order they came in: the order of a stable sort. Each point gets integer keys (each
/// float's bits mapped so that unsigned order is `total_cmp`'s, then the point's place),
/// which compare cheaper than the floats. Where the offsets across span a finite range,
/// the points are first dealt into about one bucket a point by their offset (a counting
/// sort, stable; the bucket is a non-decreasing function of the offset, so no two points
/// are out of order across buckets) and each bucket is then sorted by its keys, a few
/// points at a time; otherwise the keys are sorted at once.
fn sort_across(
    prof: &[(f64, f64, f64)],
    keys: &mut Vec<(u64, u64, u32)>,
    starts: &mut Vec<u32>,
) -> Vec<(f64, f64, f64)> {
    let ordered = |v: f64| {
        let b = v.to_bits();
        if b >> 63 == 1 {
            !b
        } else {
            b | 1 << 63
        }
    };
    let key = |k: usize, p: &(f64, f64, f64)| (ordered(p.0), ordered(p.1), k as u32);
    let n = prof.len();
    let (lo, hi) = prof
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.0), hi.max(p.0))
        });
    let span = hi - lo;
    keys.clear();
    if n < 16 || !(span.is_finite() && span > 0.0) || prof.iter().any(|p| p.0.is_nan()) {
        keys.extend(prof.iter().enumerate().map(|(k, p)| key(k, p)));
        keys.sort_unstable();
        return keys.iter().map(|k| prof[k.2 as usize]).collect();
    }
    // Bucket of an offset: (c − lo) · scale, rounded down; each step is non-decreasing in c.
    let buckets = n;
    let scale = (buckets - 1) as f64 / span;
    let bucket = |c: f64| (((c - lo) * scale) as usize).min(buckets - 1);
    // `starts[b + 1]` counts bucket b, then (prefix sums) is where bucket b + 1 begins; the
    // deal moves each bucket's start on to its end, so `starts[b]` is then bucket b's end.
    starts.clear();
    starts.resize(buckets + 1, 0);
    for p in prof {
        starts[bucket(p.0) + 1] += 1;
    }
    for b in 0..buckets {
        starts[b + 1] += starts[b];
    }
    keys.resize(n, (0, 0, 0));
    for (k, p) in prof.iter().enumerate() {
        let b = bucket(p.0);
        keys[starts[b] as usize] = key(k, p);
        starts[b] += 1;
    }
    let mut s = 0;
    for &e in &starts[..buckets] {
        let e = e as usize;
        if e - s > 1 {
            keys[s..e].sort_unstable();
        }
        s = e;
    }
    keys.iter().map(|k| prof[k.2 as usize]).collect()
}

/// Prefix sums of 1, c, c², z, c·z, z² over a sorted profile (heights relative to the
/// first point, for precision): a least-squares line over any run of its points in O(1).
pub(super) struct Sums {
    pub(super) acc: Vec<[f64; 6]>,
}

impl Sums {
    pub(super) fn new(prof: &[(f64, f64, f64)]) -> Self {
        let z0 = prof.first().map_or(0.0, |p| p.1);
        let mut acc = Vec::with_capacity(prof.len() + 1);
        let mut run = [0.0f64; 6];
        acc.push(run);
        for p in prof {
            let (c, z) = (p.0, p.1 - z0);
            let t = [1.0, c, c * c, z, c * z, z * z];
            for j in 0..6 {
                run[j] += t[j];
            }
            acc.push(run);
        }
        Self { acc }
    }

    /// Line z = a + b·c over prof[lo..hi]: (a, b, sse), heights relative to the first
    /// point. Slope 0 when the run has a single position (one scanline beside a side
    /// street's curb).
    fn line(&self, lo: usize, hi: usize) -> (f64, f64, f64) {
        let acc = &self.acc;
        let s: Vec<f64> = (0..6).map(|j| acc[hi][j] - acc[lo][j]).collect();
        let (n, sc, scc, sz, scz, szz) = (s[0], s[1], s[2], s[3], s[4], s[5]);
        let den = n * scc - sc * sc;
        let b = if den > 1e-9 * n * n {
            (n * scz - sc * sz) / den
        } else {
            0.0
        };
        let a = (sz - b * sc) / n;
        // Σ(z − a − b·c)² expanded.
        let sse = szz - 2.0 * a * sz - 2.0 * b * scz + n * a * a + 2.0 * a * b * sc + b * b * scc;
        (a, b, sse.max(0.0))
    }
}

/// Farthest a curb cut's toe may lie across the profile from its centre, metres: a cut
/// keeps the line of the curb it interrupts, so the toe stays where the track predicts it.
const CUT_MAX_OFFSET_M: f64 = 0.1;

/// Least rise of the ground behind a curb cut's toe over the road's own line, taken
/// [`CUT_RISE_AT_M`] behind the toe, metres. A 1:12 ramp rises 21 mm there, a lip of 15 mm
/// or more gives it at once; a road's crown or rut does not.
const CUT_MIN_RISE_M: f64 = 0.015;

/// Distance behind the toe at which [`CUT_MIN_RISE_M`] is measured, metres.
const CUT_RISE_AT_M: f64 = 0.25;

/// Steepest ground behind a curb cut's toe, as a slope: a ramp may climb a 250 mm
/// sidewalk over 0.5 m (1:2), far steeper than a road's crossfall, far flatter than a
/// curb's face or a car's flank.
const CUT_MAX_RAMP: f64 = 0.6;

/// Largest RMS of the two lines of a curb cut's profile about its points, metres: twice
/// the largest range noise of the scanners simulated and modelled.
const CUT_MAX_RMS_M: f64 = 0.02;

impl Profile<'_> {
    /// Finds the toe of a *curb cut* on the profile (the same points as
    /// [`Profile::toe`]): where the lip is too low for a step (0–50 mm, down to none) the toe is
    /// the break of slope between the road, falling towards the curb line, and the lip, ramp
    /// or lowered sidewalk behind it, rising away from it. The sorted points are split in two
    /// where two independent least-squares lines fit them best; the split is accepted as the
    /// toe when the road part is ground-like (slope under `profile_max_slope`), the part
    /// behind it rises no steeper than [`CUT_MAX_RAMP`] and at least [`CUT_MIN_RISE_M`] above the
    /// road's line [`CUT_RISE_AT_M`] behind the toe (and never falls below it at the toe), the
    /// lines fit within [`CUT_MAX_RMS_M`], ground is seen within 0.15 m on both sides, and the
    /// toe lies within [`CUT_MAX_OFFSET_M`] of the centre. Meant only for continuing a track
    /// along a curb line, where the prediction says where the toe is: on its own the break
    /// would be too weak a sign of a curb.
    pub fn cut_toe(&self) -> Option<ProfileToe> {
        let params = self.params;
        const MIN_SIDE: usize = 6;
        const NEAR_M: f64 = 0.15;
        let prof = self.gather();
        let m = prof.len();
        if m < 2 * MIN_SIDE {
            return None;
        }
        let sums = Sums::new(&prof);
        let z0 = prof[0].1;
        let mut best: Option<(f64, usize)> = None;
        for k in MIN_SIDE..=m - MIN_SIDE {
            if prof[k].0 - prof[k - 1].0 <= 0.0 {
                continue;
            }
            let toe = 0.5 * (prof[k - 1].0 + prof[k].0);
            if toe.abs() > CUT_MAX_OFFSET_M {
                continue;
            }
            let e = sums.line(0, k).2 + sums.line(k, m).2;
            if best.is_none_or(|(be, _)| e < be) {
                best = Some((e, k));
            }
        }
        let (sse, k) = best?;
        let toe = 0.5 * (prof[k - 1].0 + prof[k].0);
        if prof[k].0 - toe > NEAR_M || toe - prof[k - 1].0 > NEAR_M {
            return None; // no ground seen right beside the toe
        }
        // Both parts must reach far enough from the toe for their slopes to mean something.
        if toe - prof[0].0 < 2.0 * NEAR_M || prof[m - 1].0 - toe < 2.0 * NEAR_M {
            return None;
        }
        let (la, lb, _) = sums.line(0, k);
        let (ha, hb, _) = sums.line(k, m);
        if lb.abs() > params.profile_max_slope || hb > CUT_MAX_RAMP {
            return None;
        }
        let road = |c: f64| la + lb * c;
        let back = |c: f64| ha + hb * c;
        let step = back(toe) - road(toe);
        let rise = back(toe + CUT_RISE_AT_M) - road(toe + CUT_RISE_AT_M);
        let rms = (sse / m as f64).sqrt();
        if step < -0.005 || rise < CUT_MIN_RISE_M.max(rms) || rms > CUT_MAX_RMS_M {
            return None;
        }
        let a = prof
            .iter()
            .filter(|p| (p.0 - toe).abs() <= NEAR_M)
            .map(|p| p.2)
            .sum::<f64>()
            / prof
                .iter()
                .filter(|p| (p.0 - toe).abs() <= NEAR_M)
                .count()
                .max(1) as f64;
        Some(ProfileToe {
            xyz: {
                let [x, y] = self.plan_at(a, toe);
                [x, y, z0 + road(toe)]
            },
            step_m: step.max(0.0),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bend::fixture::{profile_along_y, KeptPoints};
    use crate::io::trajectory::Trajectory;

    /// The toe on a profile across a curb along y at x = 0 (0.15 m up towards +x, the
    /// sidewalk rising 2 % away from it), points every 2 cm across and 5 cm along, the road
    /// at `road(x)` for x < 0.
    fn toe_beside(road: impl Fn(f64) -> f64, params: &BendParams) -> Option<ProfileToe> {
        let (mut x, mut y, mut z) = (Vec::new(), Vec::new(), Vec::new());
        for i in 0..45 {
            for j in 0..13 {
                let px = -0.45 + 0.02 * f64::from(i) + 0.01;
                x.push(px);
                y.push(-0.3 + 0.05 * f64::from(j));
                z.push(if px < 0.0 { road(px) } else { 0.15 + 0.02 * px });
            }
        }
        let points = KeptPoints::new(x, y, z);
        let trajectory = Trajectory::default();
        let input = points.input(&trajectory);
        let grid = PointGrid::build(input.x, input.y, 0.1, |_| true);
        // Walking along +y with the curb on the right (+x).
        Profile {
            input: &input,
            grid: &grid,
            params,
            centre: [0.0, 0.0, 0.0],
            along: [0.0, 1.0],
            up: -1.0,
            half_l: 0.15,
        }
        .toe()
    }

    #[test]
    fn a_road_falling_steeply_to_the_toe_still_shows_it_and_a_rising_one_does_not() {
        let params = BendParams::default();
        // A gutter on a grade: the road falls 12 % to the toe.
        let toe = toe_beside(|x| -0.12 * x, &params).expect("a toe beside a 12 % fall");
        assert!(toe.xyz[0].abs() < 0.03, "{toe:?}");
        assert!((toe.step_m - 0.15).abs() < 0.02, "{toe:?}");
        // The same ground with the fall held to the rising limit: no toe.
        let strict = BendParams {
            profile_max_road_fall: params.profile_max_slope,
            ..BendParams::default()
        };
        assert!(toe_beside(|x| -0.12 * x, &strict).is_none());
        // A road rising 12 % to the toe, or falling 20 %, is no curb's road.
        assert!(toe_beside(|x| 0.12 * x + 0.05, &params).is_none());
        assert!(toe_beside(|x| -0.2 * x, &params).is_none());
    }

    /// [`Profile::toe_or_past_face`] on a profile across a curb along y
    /// (towards +x), its returns in columns across at `(x, z)`, five along each (every
    /// 0.12 m), as a far curb's returns lie.
    fn columns(cols: &[(f64, f64)]) -> (Option<ProfileToe>, Option<ProfileToe>) {
        let (mut x, mut y, mut z) = (Vec::new(), Vec::new(), Vec::new());
        for &(cx, cz) in cols {
            for j in -2..=2 {
                x.push(cx);
                y.push(0.12 * f64::from(j));
                z.push(cz);
            }
        }
        let points = KeptPoints::new(x, y, z);
        let trajectory = Trajectory::default();
        let input = points.input(&trajectory);
        let grid = PointGrid::build(input.x, input.y, 0.1, |_| true);
        let params = BendParams::default();
        let profile = profile_along_y(&input, &grid, &params, [0.0, 0.0, 0.0], 0.3);
        profile.toe_or_past_face()
    }

    #[test]
    fn a_sparse_curb_with_a_return_on_its_face_shows_its_toe_past_the_face() {
        // An 80 mm curb at x = 0: road columns 0.22 m apart, one column on the face 30 mm
        // up, the top's columns beyond.
        let face = [
            (-0.40, 0.0),
            (-0.18, 0.0),
            (0.01, 0.03),
            (0.06, 0.08),
            (0.28, 0.0856),
        ];
        let (toe, past) = columns(&face);
        assert!(toe.is_none(), "{toe:?}");
        let past = past.expect("a toe past the face");
        assert!(past.xyz[0].abs() < 0.1, "{past:?}");
        assert!((past.step_m - 0.08).abs() < 0.02, "{past:?}");
        // The same curb without the face's column: `toe` finds it.
        let plain: Vec<(f64, f64)> = face.iter().copied().filter(|c| c.1 != 0.03).collect();
        let (toe, past) = columns(&plain);
        assert!(toe.is_some() && past.is_none(), "{toe:?} {past:?}");
        // A ramp rising 80 mm over 0.6 m (a curb cut's) and a lone mid-height column
        // between columns 0.23 m apart are no curb.
        let ramp = [
            (-0.40, 0.0),
            (-0.18, 0.0),
            (0.0, 0.02),
            (0.15, 0.04),
            (0.30, 0.06),
            (0.42, 0.08),
        ];
        assert_eq!(columns(&ramp), (None, None));
        let wide = [(-0.40, 0.0), (-0.18, 0.0), (0.05, 0.04), (0.28, 0.08)];
        assert_eq!(columns(&wide), (None, None));
    }

    /// `sort_across(prof)` against the standard library's stable sort by `total_cmp`, bit
    /// for bit; asserts the profile had exact ties (kept in arrival order).
    fn assert_stable_sorted(prof: Vec<(f64, f64, f64)>) {
        let mut want = prof.clone();
        want.sort_by(|p, q| p.0.total_cmp(&q.0).then(p.1.total_cmp(&q.1)));
        let got = sort_across(&prof, &mut Vec::new(), &mut Vec::new());
        let bits = |v: &[(f64, f64, f64)]| -> Vec<[u64; 3]> {
            v.iter()
                .map(|p| [p.0.to_bits(), p.1.to_bits(), p.2.to_bits()])
                .collect()
        };
        assert_eq!(bits(&got), bits(&want));
        assert!(got.windows(2).any(|w| w[0].0 == w[1].0 && w[0].1 == w[1].1));
    }

    /// Positions and heights on a coarse lattice (many exact ties), the third value
    /// telling the points apart.
    fn lattice(n: u32) -> Vec<(f64, f64, f64)> {
        (0..n)
            .map(|k| {
                let c = f64::from(k.wrapping_mul(2_654_435_761) % 41) * 0.025 - 0.5;
                let z = f64::from(k.wrapping_mul(40_503) % 7) * 0.01 - 0.03;
                (c, z, f64::from(k))
            })
            .collect()
    }

    #[test]
    fn sort_across_is_the_stable_sort_by_total_cmp() {
        // With a NaN across (no finite span: the keys sorted at once).
        let mut prof = lattice(2_000);
        prof.push((-0.0, 0.0, -1.0));
        prof.push((0.0, -0.0, -2.0));
        prof.push((f64::NAN, 0.0, -3.0));
        prof.push((-1e-300, f64::INFINITY, -4.0));
        assert_stable_sorted(prof);
    }

    #[test]
    fn sort_across_by_buckets_is_the_stable_sort_by_total_cmp() {
        // Finite offsets (dealt into buckets): ±0 and a tiny negative offset share a
        // bucket, offsets a few ulp apart and the span's ends too.
        let mut prof = lattice(2_000);
        prof.push((-0.0, 0.0, -1.0));
        prof.push((0.0, -0.0, -2.0));
        prof.push((-1e-300, f64::INFINITY, -4.0));
        prof.push((0.5, 0.0, -5.0));
        prof.push((f64::from_bits(0.5f64.to_bits() - 1), 0.0, -6.0));
        prof.push((-0.5, 0.0, -7.0));
        prof.push((f64::from_bits(0.3f64.to_bits() + 2), 1.0, -8.0));
        prof.push((0.3, 1.0, -9.0));
        assert_stable_sorted(prof.clone());
        // Few points: each bucket holds one or two.
        assert_stable_sorted(
            (0..40u32)
                .map(|k| (f64::from(k * 7 % 5) * 0.1, f64::from(k % 2), f64::from(k)))
                .collect(),
        );
        // One offset only (a zero span): the keys sorted at once.
        assert_stable_sorted(
            (0..50)
                .map(|k| (0.1, f64::from(k % 3), f64::from(k)))
                .collect(),
        );
    }
}
