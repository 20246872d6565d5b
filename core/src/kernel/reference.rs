//! A plain f64 implementation of the kernel, written straight from docs/spec.md §2 and the paper
//! (§2.3–2.6) for the differential test: neighbours by walking outward from each point,
//! ρ as the difference of the two directions' angles (atan2 each) with the side rule as
//! two orientation tests, removal by |ρ| > threshold, Taubin with a copy per step, peaks by
//! scanning each window, candidates by stepping outward from the nadir.
//!
//! It also records how close each decision came to flipping (`margin_*`), so the test can
//! skip profiles where f32 rounding could legitimately decide differently.
#![allow(clippy::needless_range_loop)] // index loops read closer to the definitions
extern crate std;

use super::bend::MAX_SIDE;
use super::{KernelParams, PointStatus};
use std::vec::Vec;

/// The reference's result, in input order.
pub struct RefOut {
    pub x: Vec<f64>,
    pub z: Vec<f64>,
    pub rho: Vec<f64>,
    pub status: Vec<PointStatus>,
    pub nadir: Option<usize>,
    pub left: Option<usize>,
    pub right: Option<usize>,
    pub peaks: usize,
    /// Smallest |distance − d_b| met while walking for neighbours, and |gap − smooth_gap|.
    pub margin_m: f64,
    /// Smallest distance of a deciding angle from its threshold (irregular, τ, window max).
    pub margin_deg: f64,
}

fn dist(x: &[f64], z: &[f64], a: usize, b: usize) -> f64 {
    libm::hypot(x[a] - x[b], z[a] - z[b])
}

/// The walk outward from each point of docs/spec.md §2; returns (s, t) per point. Used to
/// count how often the kernel's sweep differs from it.
pub fn windows_walk(x: &[f64], z: &[f64], d_b: f64) -> (Vec<usize>, Vec<usize>) {
    let n = x.len();
    let (mut s, mut t) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for i in 0..n {
        let mut j = i;
        while j > 0 && i - (j - 1) <= MAX_SIDE && dist(x, z, j - 1, i) <= d_b {
            j -= 1;
        }
        s.push(j);
        let mut j = i;
        while j + 1 < n && (j + 1) - i <= MAX_SIDE && dist(x, z, j + 1, i) <= d_b {
            j += 1;
        }
        t.push(j);
    }
    (s, t)
}

/// The kernel's window rule (module docs of `bend`), evaluated literally per point:
/// s(i) = the first j ≥ max(s(i−1), i − MAX_SIDE) within d_b of p_i; t(i) = the last
/// j ≤ min(t(i+1), i + MAX_SIDE) within d_b. Updates the distance margin with every
/// comparison that decided something.
pub fn windows(x: &[f64], z: &[f64], d_b: f64, margin: &mut f64) -> (Vec<usize>, Vec<usize>) {
    let n = x.len();
    let mut s = std::vec![0usize; n];
    let mut t = std::vec![0usize; n];
    let mut prev = 0usize;
    for i in 0..n {
        let lo = prev.max(i.saturating_sub(MAX_SIDE));
        let j = (lo..=i)
            .find(|&j| {
                let d = dist(x, z, j, i);
                *margin = margin.min((d - d_b).abs());
                d <= d_b
            })
            .unwrap_or(i);
        s[i] = j;
        prev = j;
    }
    let mut next = n.saturating_sub(1);
    for i in (0..n).rev() {
        let hi = next.min(i + MAX_SIDE);
        let j = (i..=hi)
            .rev()
            .find(|&j| {
                let d = dist(x, z, j, i);
                *margin = margin.min((d - d_b).abs());
                d <= d_b
            })
            .unwrap_or(i);
        t[i] = j;
        next = j;
    }
    (s, t)
}

/// Orientation of c relative to the directed line a→b (positive: left of it).
fn orient(a: (f64, f64), b: (f64, f64), c: (f64, f64)) -> f64 {
    (b.0 - a.0) * (c.1 - a.1) - (b.1 - a.1) * (c.0 - a.0)
}

/// ρ in degrees by the paper's definition.
pub fn rho(x: &[f64], z: &[f64], s: usize, i: usize, t: usize) -> f64 {
    let (ps, pi, pt) = ((x[s], z[s]), (x[i], z[i]), (x[t], z[t]));
    let a1 = libm::atan2(pi.1 - ps.1, pi.0 - ps.0);
    let a2 = libm::atan2(pt.1 - pi.1, pt.0 - pi.0);
    let mut d = a2 - a1;
    while d <= -core::f64::consts::PI {
        d += 2.0 * core::f64::consts::PI;
    }
    while d > core::f64::consts::PI {
        d -= 2.0 * core::f64::consts::PI;
    }
    let mag = d.abs().to_degrees();
    let oi = orient(ps, pt, pi);
    let oo = orient(ps, pt, (0.0, 0.0));
    let opposite = (oi > 0.0 && oo < 0.0) || (oi < 0.0 && oo > 0.0);
    if opposite || mag == 180.0 {
        mag
    } else {
        -mag
    }
}

/// Runs the reference on raw points.
pub fn run(x0: &[f64], z0: &[f64], p: &KernelParams) -> RefOut {
    let n = x0.len();
    let d_b = f64::from(p.d_b_m);
    let mut margin_m = f64::INFINITY;
    let mut margin_deg = f64::INFINITY;

    // §2.3–2.4 on the raw line. The test's raw points lie on a 2⁻¹⁰ m grid, where squared
    // distances are exact in f32 too, so these window decisions cannot differ: no margin.
    let mut exact = f64::INFINITY;
    let (s, t) = windows(x0, z0, d_b, &mut exact);
    let thr = f64::from(p.irregular_deg);
    let mut status = std::vec![PointStatus::Kept; n];
    for i in 0..n {
        // Isolated points are judged with their adjacent points (bend::mark_irregular).
        let (si, ti) = if s[i] == i && t[i] == i && i > 0 && i + 1 < n {
            (i - 1, i + 1)
        } else {
            (s[i], t[i])
        };
        if si < i && ti > i {
            let r = rho(x0, z0, si, i, ti);
            margin_deg = margin_deg.min((r.abs() - thr).abs());
            if r.abs() > thr {
                status[i] = PointStatus::Irregular;
            }
        }
    }
    let kept: Vec<usize> = (0..n).filter(|&i| status[i] == PointStatus::Kept).collect();
    let mut x: Vec<f64> = kept.iter().map(|&i| x0[i]).collect();
    let mut z: Vec<f64> = kept.iter().map(|&i| z0[i]).collect();
    let k = kept.len();

    // §2.5: pieces split at gaps, ends of each fixed.
    let gap = f64::from(p.smooth_gap_m);
    let mut fixed = std::vec![false; k];
    for j in 0..k {
        if j == 0 || j + 1 == k {
            fixed[j] = true;
        }
        // Raw grid points again: the gap decisions are exact in f32 as well.
        if gap > 0.0 && j + 1 < k {
            let g = dist(&x, &z, j, j + 1);
            if g > gap {
                fixed[j] = true;
                fixed[j + 1] = true;
            }
        }
    }
    for step in 0..p.taubin_steps {
        let a = if step % 2 == 0 {
            f64::from(p.taubin_lambda)
        } else {
            f64::from(p.taubin_mu)
        };
        let (ox, oz) = (x.clone(), z.clone());
        for j in 0..k {
            if !fixed[j] {
                x[j] = ox[j] + a * 0.5 * ((ox[j - 1] - ox[j]) + (ox[j + 1] - ox[j]));
                z[j] = oz[j] + a * 0.5 * ((oz[j - 1] - oz[j]) + (oz[j + 1] - oz[j]));
            }
        }
    }

    // ρ on the smoothed line.
    let (s, t) = windows(&x, &z, d_b, &mut margin_m);
    // Distances against the smoothing gap (0: no gaps), on smoothed points: recorded in the
    // margin.
    let apart = |a: usize, b: usize, margin_m: &mut f64| {
        if gap <= 0.0 {
            return false;
        }
        let g = dist(&x, &z, a, b);
        *margin_m = margin_m.min((g - gap).abs());
        g > gap
    };
    // A window cut short by the line's end or a gap gives no candidate.
    let mut cut = std::vec![false; k];
    for j in 0..k {
        cut[j] = s[j] == 0
            || t[j] + 1 >= k
            || apart(s[j] - 1, s[j], &mut margin_m)
            || apart(t[j], t[j] + 1, &mut margin_m);
    }
    let has = |j: usize| s[j] < j && t[j] > j;
    let r: Vec<f64> = (0..k)
        .map(|j| {
            if has(j) {
                rho(&x, &z, s[j], j, t[j])
            } else {
                0.0
            }
        })
        .collect();

    // §2.6.
    let (tmin, tmax) = (f64::from(p.tau_min_deg), f64::from(p.tau_max_deg));
    let mut peak = std::vec![false; k];
    for j in 0..k {
        if !has(j) {
            continue;
        }
        margin_deg = margin_deg.min((r[j] - tmin).abs()).min((r[j] - tmax).abs());
        if r[j] > tmin && r[j] < tmax {
            let mut ok = true;
            for m in s[j]..=t[j] {
                if m != j {
                    margin_deg = margin_deg.min((r[j] - r[m]).abs());
                    ok &= r[j] >= r[m];
                }
            }
            peak[j] = ok;
        }
    }
    let mut nadir: Option<usize> = None;
    for j in 0..k {
        if z[j] < 0.0 && nadir.is_none_or(|b| x[j].abs() < x[b].abs()) {
            nadir = Some(j);
        }
    }
    let (mut left, mut right) = (None, None);
    if let Some(nd) = nadir {
        for m in 0..k {
            let mut cands: Vec<usize> = Vec::new();
            if nd >= m {
                cands.push(nd - m);
            }
            if m > 0 && nd + m < k {
                cands.push(nd + m);
            }
            if cands.len() == 2 && x[cands[1]].abs() < x[cands[0]].abs() {
                cands.swap(0, 1);
            }
            for c in cands {
                if !peak[c] || cut[c] {
                    continue;
                }
                if x[c] > 0.0 && left.is_none() {
                    left = Some(c);
                } else if x[c] < 0.0 && right.is_none() {
                    right = Some(c);
                }
            }
        }
    }

    // Back to input order.
    let mut ox = x0.to_vec();
    let mut oz = z0.to_vec();
    let mut orho = std::vec![0.0; n];
    for (j, &i) in kept.iter().enumerate() {
        ox[i] = x[j];
        oz[i] = z[j];
        orho[i] = r[j];
        if !has(j) {
            status[i] = PointStatus::NoNeighbour;
        }
    }
    RefOut {
        x: ox,
        z: oz,
        rho: orho,
        status,
        nadir: nadir.map(|j| kept[j]),
        left: left.map(|j| kept[j]),
        right: right.map(|j| kept[j]),
        peaks: peak.iter().filter(|&&b| b).count(),
        margin_m,
        margin_deg,
    }
}
