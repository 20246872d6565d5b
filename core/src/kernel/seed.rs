//! Peaks, nadir and the per-scanline seed candidates (Honma et al. §2.6, docs/spec.md §2).
//!
//! - Nadir: the point with the smallest |x′| among points with z′ < 0 (first one on a tie).
//! - Peak: ρ_i is the largest ρ within i's d_b window (ties count: ρ_i ≥ every ρ_j in the
//!   window) and τ_min < ρ_i < τ_max; a point without a neighbour on a side has no ρ and
//!   is never a peak.
//! - Candidates: walking outward from the nadir in scan order (both ways at once), the
//!   first peak with x′ > 0 is the left candidate and the first with x′ < 0 the right one.
//!   "First" is the smallest |k − nadir|; a tie between the two directions goes to the
//!   smaller |x′| (nearer the vehicle), then the lower index. A peak whose window is cut
//!   short by a gap or the line's end ([`super::bend::window_cut`]) is passed over.
//!
//! The window maximum comes from a monotone deque over the same two-index windows as ρ
//! (both ends only move forward), fed lazily (see [`seed_candidates`]), so the whole pass
//! is O(n). Its length never exceeds 2·[`MAX_SIDE`] + 2 = [`DEQUE_LEN`] (at most the
//! indices between the previous s and the current t).

use super::bend::MAX_SIDE;
use super::PointStatus;

/// Capacity of the peak search's deque (a power of two ≥ 2·MAX_SIDE + 2).
pub(crate) const DEQUE_LEN: usize = 512;
const _: () = assert!(DEQUE_LEN >= 2 * MAX_SIDE + 2 && DEQUE_LEN.is_power_of_two());

/// The smallest |x′| among points with z′ < 0.
pub(crate) fn nadir(x: &[f32], z: &[f32]) -> Option<usize> {
    let mut best: Option<(usize, f32)> = None;
    for (i, (&xi, &zi)) in x.iter().zip(z).enumerate() {
        let ax = crate::math::abs(xi);
        if zi < 0.0 && best.is_none_or(|(_, b)| ax < b) {
            best = Some((i, ax));
        }
    }
    best.map(|(i, _)| i)
}

/// What the peak pass found.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Seeds {
    /// Number of peaks.
    pub peaks: u32,
    /// Points without a neighbour on a side.
    pub no_neighbour: u32,
    /// Left candidate (x′ > 0), compact index.
    pub left: Option<usize>,
    /// Right candidate (x′ < 0), compact index.
    pub right: Option<usize>,
}

/// The read-only inputs of [`seed_candidates`].
#[derive(Clone, Copy)]
pub(crate) struct SeedArgs<'a> {
    /// Smoothed x′ of the kept points.
    pub x: &'a [f32],
    /// Smoothed z′ of the kept points.
    pub z: &'a [f32],
    /// The smoothing gap squared (0: none).
    pub gap2: f32,
    /// ρ per kept point.
    pub rho: &'a [f32],
    /// k − s(k) per kept point.
    pub s_off: &'a [u8],
    /// τ_min, degrees.
    pub tau_min: f32,
    /// τ_max, degrees.
    pub tau_max: f32,
    /// The nadir, compact index.
    pub nadir: Option<usize>,
    /// In a lean pass, the points whose ρ was computed (every point with ρ above τ_min
    /// among them), highest index first, if listed (`bend::windows_angles`).
    pub exact: Option<&'a [u16]>,
}

/// Peak search over the smoothed kept points. `s_off[k]` = k − s(k) and, on entry,
/// `aux[k]` = t(k) − k (from `bend::windows`); on return `aux[k]` holds the point's status
/// as `u8` ([`PointStatus::Kept`] or
/// [`PointStatus::NoNeighbour`]).
///
/// The window maximum is only needed where ρ_k is inside (τ_min, τ_max) — near curbs and
/// objects, a few percent of the points — so the deque is fed lazily: at such a k it takes
/// the indices from where it stopped (or from s(k), starting afresh, when it stopped before
/// s(k)) up to t(k). Both window ends only move forward, so every index enters at most
/// once: O(n) in the worst case, and nearly nothing on plain road.
///
/// Without `STATUS` (a lean pass, see `Kernel::set_lean_rho`) `aux` is only read, and
/// the points without a neighbour are not counted (the lean sweep counted them,
/// `bend::windows_angles`): only the points with ρ above τ_min are looked at, found by a
/// scan of ρ alone. The others cannot be peaks, and a point without a neighbour has ρ = 0,
/// not above τ_min (≥ 0); its window is still checked before it is taken as a peak.
pub(crate) fn seed_candidates<const STATUS: bool>(
    args: SeedArgs<'_>,
    aux: &mut [u8],
    deque: &mut [u16; DEQUE_LEN],
) -> Seeds {
    const M: usize = DEQUE_LEN - 1;
    let SeedArgs {
        x,
        z,
        gap2,
        rho,
        s_off,
        tau_min,
        tau_max,
        nadir,
        exact,
    } = args;
    let n = x.len();
    let (rho, s_off, aux) = (&rho[..n], &s_off[..n], &mut aux[..n]);
    let mut out = Seeds::default();
    // Best candidate per side: (index, |k − nadir|, |x|).
    let mut left: Option<(usize, usize, f32)> = None;
    let mut right: Option<(usize, usize, f32)> = None;
    let (mut head, mut tail) = (0usize, 0usize);
    let mut next = 0usize;
    let mut at = 0usize;
    // The listed points, taken from the back (lowest index first).
    let mut listed = exact.unwrap_or(&[]);
    while at < n {
        if !STATUS {
            if exact.is_some() {
                // The next listed point (ρ may still be at or below τ_min: tested below).
                match listed.split_last() {
                    Some((&k, rest)) => {
                        at = usize::from(k);
                        listed = rest;
                        if at >= n {
                            break;
                        }
                    }
                    None => break,
                }
            } else {
                // The next point with ρ above τ_min (a scan of ρ alone).
                match rho[at..].iter().position(|&r| r > tau_min) {
                    Some(o) => at += o,
                    None => break,
                }
            }
        }
        let k = at;
        at += 1;
        let s = k - usize::from(s_off[k]);
        let t = k + usize::from(aux[k]);
        // No neighbour on a side: rare (line ends, isolated points), so a branch rather
        // than a branch-free count.
        if s == k || t == k {
            if STATUS {
                aux[k] = PointStatus::NoNeighbour as u8;
                out.no_neighbour += 1;
            }
            continue;
        }
        if STATUS {
            aux[k] = PointStatus::Kept as u8;
        }
        let r = rho[k];
        if !(r > tau_min && r < tau_max) {
            continue;
        }
        // The window maximum over [s, t].
        if next < s {
            head = tail;
            next = s;
        }
        while next <= t {
            let v = rho[next];
            while tail > head && rho[usize::from(deque[(tail - 1) & M])] <= v {
                tail -= 1;
            }
            // next ≤ k + MAX_SIDE < n ≤ u16::MAX (the kernel caps N).
            deque[tail & M] = next as u16;
            tail += 1;
            next += 1;
        }
        // Never empties: t itself is in the deque or was popped by a later, larger one.
        while tail > head + 1 && usize::from(deque[head & M]) < s {
            head += 1;
        }
        if r < rho[usize::from(deque[head & M])] {
            continue;
        }
        out.peaks += 1;
        let Some(nd) = nadir else { continue };
        // A window cut short by a gap or the line's end gives no candidate (rare: peaks only).
        if super::bend::window_cut(x, z, gap2, s, t) {
            continue;
        }
        let xk = x[k];
        let dist = k.abs_diff(nd);
        let ax = crate::math::abs(xk);
        let better = |b: Option<(usize, usize, f32)>| match b {
            None => true,
            Some((_, bd, bx)) => dist < bd || (dist == bd && ax < bx),
        };
        if xk > 0.0 && better(left) {
            left = Some((k, dist, ax));
        } else if xk < 0.0 && better(right) {
            right = Some((k, dist, ax));
        }
    }
    out.left = left.map(|b| b.0);
    out.right = right.map(|b| b.0);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::bend::windows;

    #[test]
    fn nadir_is_smallest_abs_x_below_the_scanner() {
        let x = [3.0f32, 0.2, -0.05, 0.01, -2.0];
        let z = [-2.0f32, -2.0, -2.0, 1.0, -2.0];
        // Index 3 has the smallest |x| but is above the scanner.
        assert_eq!(nadir(&x, &z), Some(2));
        assert_eq!(nadir(&x[..2], &[1.0, 1.0]), None);
        assert_eq!(nadir(&[], &[]), None);
    }

    /// Runs the peak pass on a line with given ρ (windows from positions).
    fn peaks_of(x: &[f32], rho: &[f32], d2: f32, nadir: Option<usize>) -> (Seeds, [u8; 32]) {
        let n = x.len();
        let z = [-2.0f32; 32];
        let mut aux = [0u8; 32];
        let mut s_off = [0u8; 32];
        windows(x, &z[..n], d2, &mut s_off[..n], &mut aux[..n]);
        let mut dq = [0u16; DEQUE_LEN];
        let args = SeedArgs {
            x,
            z: &z[..n],
            gap2: 0.09,
            rho,
            s_off: &s_off[..n],
            tau_min: 35.0,
            tau_max: 150.0,
            nadir,
            exact: None,
        };
        let seeds = seed_candidates::<true>(args, &mut aux[..n], &mut dq);
        (seeds, aux)
    }

    #[test]
    fn peaks_are_window_maxima_in_range_and_candidates_are_first_each_side() {
        // 16 points every 0.05 m from x = −0.4 to 0.35; d_b = 0.1 → 2 points each side.
        let x: [f32; 16] = core::array::from_fn(|i| -0.4 + 0.05 * i as f32);
        let mut rho = [0.0f32; 16];
        rho[1] = 80.0; // peak, right side, 7 steps from nadir 8
        rho[2] = 50.0; // within the window of 1: not a peak
        rho[4] = 60.0; // peak, right side, 4 from the nadir → right candidate
        rho[10] = 40.0; // not a peak: 11 is larger and within d_b
        rho[11] = 45.0; // peak, left, 3 from the nadir → left candidate
        rho[14] = 170.0; // above τ_max: not a peak
                         // End points 0 and 15 have no neighbour on one side.
        let (s, aux) = peaks_of(&x, &rho, 0.0101, Some(8));
        assert_eq!(s.peaks, 3);
        assert_eq!(s.right, Some(4));
        assert_eq!(s.left, Some(11));
        assert_eq!(s.no_neighbour, 2);
        assert_eq!(aux[0], PointStatus::NoNeighbour as u8);
        assert_eq!(aux[15], PointStatus::NoNeighbour as u8);
        assert_eq!(aux[7], PointStatus::Kept as u8);
        // Without a nadir: peaks, but no candidates.
        let (s, _) = peaks_of(&x, &rho, 0.0101, None);
        assert_eq!((s.peaks, s.left, s.right), (3, None, None));
    }

    #[test]
    fn a_lean_pass_visiting_listed_points_finds_what_its_scan_finds() {
        let x: [f32; 16] = core::array::from_fn(|i| -0.4 + 0.05 * i as f32);
        let z = [-2.0f32; 16];
        let mut rho = [35.0f32; 16]; // τ_min: a skipped point
        rho[0] = 0.0; // no neighbour
        rho[1] = 80.0;
        rho[2] = 50.0;
        rho[4] = 60.0;
        rho[6] = 20.0; // computed, below τ_min
        rho[10] = 40.0;
        rho[11] = 45.0;
        rho[14] = 170.0;
        let (mut s_off, mut t_off) = ([0u8; 16], [0u8; 16]);
        windows(&x, &z, 0.0101, &mut s_off, &mut t_off);
        let run = |exact: Option<&[u16]>| {
            let mut dq = [0u16; DEQUE_LEN];
            let mut aux = t_off;
            let args = SeedArgs {
                x: &x,
                z: &z,
                gap2: 0.09,
                rho: &rho,
                s_off: &s_off,
                tau_min: 35.0,
                tau_max: 150.0,
                nadir: Some(8),
                exact,
            };
            seed_candidates::<false>(args, &mut aux, &mut dq)
        };
        let scanned = run(None);
        assert_eq!(
            (scanned.peaks, scanned.left, scanned.right),
            (3, Some(11), Some(4))
        );
        // Every computed point, highest first, some of them at or below τ_min.
        assert_eq!(run(Some(&[14, 11, 10, 6, 4, 2, 1])), scanned);
        // Only those above τ_min.
        assert_eq!(run(Some(&[14, 11, 10, 4, 2, 1])), scanned);
        // An empty list: nothing above τ_min, nothing found.
        assert_eq!(run(Some(&[])).peaks, 0);
    }

    #[test]
    fn equal_maxima_are_both_peaks() {
        let x: [f32; 8] = core::array::from_fn(|i| 0.1 + 0.05 * i as f32);
        let mut rho = [0.0f32; 8];
        rho[3] = 90.0;
        rho[4] = 90.0;
        let (s, _) = peaks_of(&x, &rho, 0.0101, Some(0));
        assert_eq!(s.peaks, 2);
        assert_eq!(s.left, Some(3));
    }
}
