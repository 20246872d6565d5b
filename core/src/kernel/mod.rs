//! The per-scanline kernel (Honma et al. §2.3–2.6): bend angle ρ, removal of irregular
//! points, Taubin smoothing, ρ again on the smoothed line, peaks, and the first peak on each
//! side of the nadir as that side's seed candidate.
//!
//! # One line, in place, O(n)
//!
//! [`Kernel::process`] works on the assembled [`Line`] itself:
//!
//! 1. [`bend`]: neighbour windows by two sweeps (s forward, t backward), the raw bend angle
//!    compared with the irregular threshold without atan2 (§2.3–2.4); non-finite points
//!    are set aside too.
//! 2. The kept points are moved to the front of the line, in order (a Lomuto partition:
//!    each kept point swaps with the first set-aside one), so smoothing runs on contiguous
//!    arrays.
//! 3. [`smooth`]: Taubin smoothing of the kept points in place (§2.5).
//! 4. [`bend`] again on the smoothed points: windows and the signed ρ in degrees.
//! 5. [`seed`]: nadir, peaks, the left and right candidates (§2.6).
//! 6. The partition is undone by replaying its swaps backwards, so every output slice is
//!    indexed by input point again; set-aside points get their raw coordinates back.
//!
//! With a region of interest ([`KernelParams::roi`]), the points inside it are first moved
//! to the front the same way, tags included (step 0), and steps 1–6 run on them alone. That
//! partition is not undone: the line's output lists the points inside in input order,
//! then the points outside (raw coordinates, ρ = 0, [`PointStatus::OutsideRoi`]) in the
//! partition's order; the tags join each point to its source. Undoing it cost more than
//! the rest of the kernel saved on the points outside (`docs/benchmarks.md`).
//!
//! # Lean pass (candidates mode, [`Kernel::set_lean_rho`])
//!
//! A candidates packet carries the nadir, the two candidates and the counts, nothing else.
//! With the lean pass on (the firmware's choice; off by default), a line in candidates mode
//! computes no more than that needs: no arctangent where ρ is certainly below τ_min
//! ([`bend::LowCut`]), the region's points compacted rather than partitioned, the kept
//! points' partition not undone (only the three indices mapped back), no per-point
//! statuses, the nadir and the points without a neighbour found inside the smoothed pass's
//! sweep, and the peak pass looking only at points whose ρ is above τ_min (on the M4F those
//! the sweep lists as computed). The packet is the same byte for byte (tested, and compared on whole streams by `firmware/check.sh`).
//!
//! # Memory
//!
//! Per point of capacity `N`: the line's x′, z′, tag (12 bytes) plus the kernel's ρ (`f32`),
//! status (`u8`) and two `u8` of working space (the window's ends as offsets; the right one
//! later holds the status of a kept point) — 19 bytes — plus a 1 KiB deque for the peak search,
//! the lean pass's list of points with an exact ρ (512 bytes) and the parameters.
//! ρ's buffer doubles as the smoothing scratch before ρ is computed.

use crate::math::{self, Maths};
use crate::scanline::Line;

pub mod bend;
mod params;
#[cfg(all(test, feature = "libm"))]
mod reference;
mod seed;
mod smooth;
#[cfg(test)]
mod synth;
/// The config packet's word count, defined by the wire format and re-exported beside the
/// parameters that fill it.
pub use crate::wire::CONFIG_WORDS;
pub use params::{KernelParams, OutputMode, Param, ParamsError, Roi};

/// What happened to one input point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u8)]
#[non_exhaustive]
pub enum PointStatus {
    /// Kept, smoothed, and has a bend angle on the smoothed line.
    Kept = 0,
    /// Removed as irregular (§2.4): |ρ| on the raw line above the threshold.
    Irregular = 1,
    /// Kept, but has no neighbour within d_b on one side, so no ρ (ρ reported as 0).
    NoNeighbour = 2,
    /// Removed before anything else: x′ or z′ is NaN, infinite or beyond ±2000 m
    /// (`MAX_COORD_M`).
    NonFinite = 3,
    /// Outside the region of interest ([`KernelParams::roi`]): not processed, raw
    /// coordinates, ρ reported as 0. Wire version 2.
    OutsideRoi = 4,
}

impl PointStatus {
    /// The status with wire value `v`, if any.
    pub fn from_u8(v: u8) -> Option<Self> {
        match v {
            0 => Some(Self::Kept),
            1 => Some(Self::Irregular),
            2 => Some(Self::NoNeighbour),
            3 => Some(Self::NonFinite),
            4 => Some(Self::OutsideRoi),
            _ => None,
        }
    }
}

/// Counters of one scanline (every point that entered is in exactly one of the
/// status counts).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct KernelCounters {
    /// Points that entered the kernel.
    pub points_in: u32,
    /// Points with status [`PointStatus::Kept`].
    pub kept: u32,
    /// Points with status [`PointStatus::Irregular`].
    pub irregular: u32,
    /// Points with status [`PointStatus::NoNeighbour`].
    pub no_neighbour: u32,
    /// Points with status [`PointStatus::NonFinite`].
    pub non_finite: u32,
    /// Peaks found (§2.6).
    pub peaks: u32,
    /// Neighbour windows (raw and smoothed pass) that stopped at [`bend::MAX_SIDE`] points
    /// with the next point still within d_b (degenerate input: many returns on one spot).
    pub capped_windows: u32,
    /// Pieces the line was smoothed in (split at gaps, see [`KernelParams::smooth_gap_m`]).
    pub smooth_pieces: u32,
    /// Points with status [`PointStatus::OutsideRoi`].
    pub outside_roi: u32,
}

/// The kernel's result for one scanline, borrowed from the kernel's buffers (no copies).
/// Index `i` of every slice is input point `i` of the line — or, with a region of
/// interest, the points inside in input order followed by the points outside (join by
/// `tag`).
pub struct ScanlineOutput<'a> {
    /// Scanline number in the stream.
    pub index: u32,
    /// Absolute time of the line's first point, nanoseconds.
    pub start_time_ns: u64,
    /// Hash of the [`KernelParams`] that produced this output.
    pub params_hash: u32,
    /// Per point: the pass-through tag.
    pub tag: &'a [u32],
    /// Per point: smoothed x′ in metres (raw x′ for irregular and non-finite points).
    pub x_m: &'a [f32],
    /// Per point: smoothed z′ in metres (raw z′ for irregular and non-finite points).
    pub z_m: &'a [f32],
    /// Per point: bend angle ρ in degrees on the smoothed line, (−180, 180]; 0 where the
    /// status is not [`PointStatus::Kept`].
    pub rho_deg: &'a [f32],
    /// Per point: what happened to it.
    pub status: &'a [PointStatus],
    /// Index of the nadir point (smallest |x′| with z′ < 0), if any.
    pub nadir: Option<u16>,
    /// Index of the left seed candidate (first peak outward from the nadir with x′ > 0).
    pub left: Option<u16>,
    /// Index of the right seed candidate (first peak outward from the nadir with x′ < 0).
    pub right: Option<u16>,
    /// Points of the line dropped by assembly because the line was over capacity.
    pub truncated: u32,
    /// Counters for this line.
    pub counters: KernelCounters,
    /// What the parameters in force ask to send for the line.
    pub output_mode: OutputMode,
}

/// Length of [`Kernel`]'s list of points with an exact ρ in a lean pass; a line with more
/// of them has its peaks found by a scan of ρ instead (the same result).
const EXACT_LEN: usize = 256;

/// Values derived from the parameters once, not per line.
#[derive(Clone, Copy, Debug)]
struct Derived {
    d2: f32,
    /// The smoothing gap squared (0: lines are never split at gaps).
    gap2: f32,
    irregular: bend::Threshold,
    /// Where a lean ρ pass may skip the arctangent ([`Kernel::set_lean_rho`]).
    low_cut: bend::LowCut,
}

impl Derived {
    /// Stands in until [`Derived::new`] has run (never used for a line).
    const PENDING: Self = Self {
        d2: 0.0,
        gap2: 0.0,
        irregular: bend::Threshold::PENDING,
        low_cut: bend::LowCut::NONE,
    };

    fn new(p: &KernelParams) -> Self {
        Self {
            d2: p.d_b_m * p.d_b_m,
            gap2: p.smooth_gap_m * p.smooth_gap_m,
            irregular: bend::Threshold::new(p.irregular_deg),
            low_cut: bend::LowCut::new(p.tau_min_deg),
        }
    }
}

/// The per-scanline kernel with its fixed-size working memory for lines of up to `N` points
/// (`N` ≤ 65 535, so that every index fits the `u16` of the output).
pub struct Kernel<const N: usize> {
    params: KernelParams,
    params_hash: u32,
    derived: Derived,
    /// ρ per point (smoothing scratch before that).
    rho: [f32; N],
    /// Status per input point.
    status: [PointStatus; N],
    /// Per point: t(i) − i, then the status of a kept point (compact order).
    aux: [u8; N],
    /// Per point: i − s(i).
    s_off: [u8; N],

    /// The peak search's window-maximum deque.
    deque: [u16; seed::DEQUE_LEN],
    /// The points whose ρ a lean pass computed (`bend::windows_angles`), for the peak
    /// search to visit instead of scanning ρ.
    exact: [u16; EXACT_LEN],
    /// `params_hash` and `derived` are still to be computed from `params` (a kernel made
    /// by the `const` [`Kernel::new`] computes them on its first line).
    fresh: bool,
    /// In candidates mode, ρ only where the candidates packet can depend on it
    /// ([`Kernel::set_lean_rho`]).
    lean_rho: bool,
}

impl<const N: usize> Kernel<N> {
    /// A kernel running `params` (taken as they are; [`Kernel::set_params`] checks them).
    ///
    /// `const`, so that a kernel can be a `static` (on the firmware, built in place rather
    /// than passed through a small stack): the values derived from the parameters (their
    /// hash, the irregular threshold's cosine and sine — libm is not `const`) are computed
    /// when the first line is processed.
    pub const fn new(params: KernelParams) -> Self {
        const { assert!(N <= u16::MAX as usize, "Kernel<N>: N must fit a u16 index") };
        Self {
            params_hash: 0,
            derived: Derived::PENDING,
            params,
            rho: [0.0; N],
            status: [PointStatus::Kept; N],
            aux: [0; N],
            s_off: [0; N],
            deque: [0; seed::DEQUE_LEN],
            exact: [0; EXACT_LEN],
            fresh: true,
            lean_rho: false,
        }
    }

    /// The kernel [`Kernel::new`]`(params)` gives, without rewriting its per-point buffers:
    /// a line writes every entry it reads (the kernel holds no state across lines).
    pub fn restart(&mut self, params: KernelParams) {
        let Self {
            params: p,
            params_hash,
            derived,
            rho: _,
            status: _,
            aux: _,
            s_off: _,
            deque: _,
            exact: _,
            fresh,
            lean_rho,
        } = self;
        *p = params;
        *params_hash = 0;
        *derived = Derived::PENDING;
        *fresh = true;
        *lean_rho = false;
    }

    /// The parameters in force.
    pub fn params(&self) -> &KernelParams {
        &self.params
    }

    /// Replaces the parameters after checking them; on error the old ones stay.
    pub fn set_params(&mut self, params: KernelParams) -> Result<(), ParamsError> {
        params.validate()?;
        self.params = params;
        self.params_hash = params.hash();
        self.derived = Derived::new(&params);
        self.fresh = false;
        Ok(())
    }

    /// With `on`, lines whose parameters ask for [`OutputMode::Candidates`] get ρ only
    /// where the candidates packet can depend on it: a kept point whose bend angle is
    /// certainly more than 1° below τ_min (the peak threshold) is given τ_min instead of
    /// its exact ρ, which spares the arctangent on most points of a road; and only the
    /// nadir and the two candidates are moved back to their input index (the region's
    /// partition keeps no points outside, the kept points' partition is not undone). The
    /// nadir, the candidates with every value the packet carries (tag, x′, z′, ρ, status,
    /// index) and every count come out as without it, so the candidates packet is the
    /// same byte for byte; the per-point slices of [`ScanlineOutput`] hold meaningful
    /// values at those three indices only. Off by default (every slice exact, whatever
    /// the mode); the firmware, which sends nothing else, turns it on.
    pub fn set_lean_rho(&mut self, on: bool) {
        self.lean_rho = on;
    }

    /// Processes one assembled line in place and returns the result borrowed from the
    /// kernel's buffers and the line.
    pub fn process<'a>(&'a mut self, line: &'a mut Line<N>) -> ScanlineOutput<'a> {
        self.process_with::<math::Selected>(line)
    }

    /// [`Kernel::process`] with an explicit maths backend (the micromath tolerance test
    /// runs both backends in one build).
    pub(crate) fn process_with<'a, M: Maths>(
        &'a mut self,
        line: &'a mut Line<N>,
    ) -> ScanlineOutput<'a> {
        if self.fresh {
            self.params_hash = self.params.hash();
            self.derived = Derived::new(&self.params);
            self.fresh = false;
        }
        let n_all = line.len.min(N);
        let p = self.params;
        let Derived {
            d2,
            gap2,
            irregular,
            low_cut,
        } = self.derived;
        // What a candidates packet does not carry is not computed (`set_lean_rho`).
        let lean = self.lean_rho && p.output_mode() == OutputMode::Candidates;
        // 0. The points inside the region of interest to the front, in order.
        let n = match p.roi() {
            Some(roi) if lean => roi_compact(
                &mut line.x_m[..n_all],
                &mut line.z_m[..n_all],
                &mut line.tag[..n_all],
                roi,
            ),
            Some(roi) => roi_partition(
                &mut line.x_m[..n_all],
                &mut line.z_m[..n_all],
                &mut line.tag[..n_all],
                roi,
            ),
            None => n_all,
        };
        let mut c = KernelCounters {
            points_in: n_all as u32,
            outside_roi: (n_all - n) as u32,
            ..KernelCounters::default()
        };
        let x = &mut line.x_m[..n];
        let z = &mut line.z_m[..n];
        let rho = &mut self.rho[..n];
        let status = &mut self.status[..n];
        let aux = &mut self.aux[..n];

        // 1. §2.3–2.4 on the raw line.
        let s_off = &mut self.s_off[..n];
        // Inside a region that lies within ±MAX_COORD_M every point is in range.
        let in_range = p.roi().is_some_and(|r| {
            let m = bend::MAX_COORD_M;
            [r.x_min, r.x_max, r.z_min, r.z_max]
                .iter()
                .all(|v| (-m..=m).contains(v))
        });
        let (capped, irr, non_finite) =
            bend::windows_marked(x, z, d2, s_off, aux, irregular, status, in_range);
        c.capped_windows += capped;
        c.irregular = irr;
        c.non_finite = non_finite;
        let kept = n - (irr + non_finite) as usize;

        // 2. Kept points to the front, in order.
        // Points before the first set-aside one stay where they are.
        let first_out = if kept < n {
            status
                .iter()
                .position(|st| *st != PointStatus::Kept)
                .unwrap_or(n)
        } else {
            n
        };
        if kept < n {
            partition(x, z, status, first_out);
        }

        // 3. §2.5 on the kept points; ρ's buffer is the scratch.
        let (xk, zk) = (&mut x[..kept], &mut z[..kept]);
        c.smooth_pieces = smooth::taubin_smooth(
            xk,
            zk,
            rho,
            p.smooth_gap_m,
            p.taubin_steps,
            p.taubin_lambda,
            p.taubin_mu,
        );

        // 4. ρ on the smoothed line.
        let s_off = &mut s_off[..kept];
        let (t_off, rk) = (&mut aux[..kept], &mut rho[..kept]);
        let ex = &mut self.exact;
        let (capped, swept_nadir, lone, listed) = if lean {
            bend::windows_angles::<M, true>(xk, zk, d2, s_off, t_off, rk, low_cut, ex)
        } else {
            let none = bend::LowCut::NONE;
            bend::windows_angles::<M, false>(xk, zk, d2, s_off, t_off, rk, none, ex)
        };
        c.capped_windows += capped;
        if !lean {
            rho[kept..].fill(0.0);
        }

        // 5. §2.6: nadir, peaks, candidates (compact indices).
        let nadir = swept_nadir.unwrap_or_else(|| seed::nadir(xk, zk));
        let mut nadir_status = PointStatus::Kept;
        if let Some(k) = nadir.filter(|_| lean) {
            // The candidates packet carries the nadir's ρ and status: as without `lean`.
            let (s, t) = (k - usize::from(s_off[k]), k + usize::from(aux[k]));
            if s != k && t != k {
                rho[k] = bend::bend_angle_deg::<M>(xk, zk, s, k, t);
            } else {
                nadir_status = PointStatus::NoNeighbour;
            }
        }
        let args = seed::SeedArgs {
            x: xk,
            z: zk,
            gap2,
            rho: &rho[..kept],
            s_off,
            tau_min: p.tau_min_deg,
            tau_max: p.tau_max_deg,
            nadir,
            exact: listed.map(|k| &self.exact[..k]),
        };
        let seeds = if lean {
            // Statuses of the candidates are Kept (peaks have both neighbours).
            seed::seed_candidates::<false>(args, &mut aux[..kept], &mut self.deque)
        } else {
            seed::seed_candidates::<true>(args, &mut aux[..kept], &mut self.deque)
        };
        c.peaks = seeds.peaks;
        // The lean peak pass leaves the points without a neighbour to the sweep's count.
        c.no_neighbour = if lean { lone } else { seeds.no_neighbour };
        c.kept = kept as u32 - c.no_neighbour;

        // 6. Back to input order: replay the partition's swaps backwards.
        let mut idx = [nadir, seeds.left, seeds.right];
        if lean {
            // Only the three points the packet carries go back to their input index.
            let st = [nadir_status, PointStatus::Kept, PointStatus::Kept];
            let vals =
                core::array::from_fn::<_, 3, _>(|j| idx[j].map(|k| (x[k], z[k], rho[k], st[j])));
            if kept < n {
                idx = lean_unmap(status, first_out, idx);
            }
            for (i, v) in idx.iter().zip(vals) {
                if let (Some(i), Some((xv, zv, rv, st))) = (*i, v) {
                    (x[i], z[i], rho[i], status[i]) = (xv, zv, rv, st);
                }
            }
        } else if kept == n {
            for (st, &a) in status.iter_mut().zip(aux.iter()) {
                *st = status_of(a);
            }
        } else {
            idx = unpartition(x, z, rho, status, aux, first_out, kept, idx);
        }
        // 7. The points outside the region of interest, behind the others.
        if !lean {
            self.rho[n..n_all].fill(0.0);
            self.status[n..n_all].fill(PointStatus::OutsideRoi);
        }
        let [nadir, left, right] = idx.map(|o| o.map(|i| i as u16));

        ScanlineOutput {
            index: line.index,
            start_time_ns: line.start_time_ns,
            params_hash: self.params_hash,
            tag: &line.tag[..n_all],
            x_m: &line.x_m[..n_all],
            z_m: &line.z_m[..n_all],
            rho_deg: &self.rho[..n_all],
            status: &self.status[..n_all],
            nadir,
            left,
            right,
            truncated: line.truncated,
            counters: c,
            output_mode: p.output_mode(),
        }
    }
}

/// Step 2 of [`Kernel::process`]: the kept points to the front, in order (a Lomuto
/// partition from the first set-aside point, `first_out`).
#[inline(never)] // its own registers, as `unpartition`
fn partition(x: &mut [f32], z: &mut [f32], status: &[PointStatus], first_out: usize) {
    let n = status.len();
    let (x, z) = (&mut x[..n], &mut z[..n]);
    let mut w = first_out;
    for (i, st) in status.iter().enumerate().skip(first_out + 1) {
        if *st == PointStatus::Kept {
            x.swap(w, i);
            z.swap(w, i);
            w += 1;
        }
    }
}

/// Step 6 of [`Kernel::process`] when points were set aside: replays the partition's swaps
/// backwards (points before `first_out` never moved), sets the kept points' statuses from
/// `aux`, and maps the compact indices `idx` back to input indices.
#[allow(clippy::too_many_arguments)]
#[inline(never)] // its own registers: inlined, it spills the peak search's
fn unpartition(
    x: &mut [f32],
    z: &mut [f32],
    rho: &mut [f32],
    status: &mut [PointStatus],
    aux: &[u8],
    first_out: usize,
    kept: usize,
    idx: [Option<usize>; 3],
) -> [Option<usize>; 3] {
    let n = status.len();
    let (x, z, rho) = (&mut x[..n], &mut z[..n], &mut rho[..n]);
    // The indices to map as plain integers (`usize::MAX`: none): cheaper to compare.
    let want = idx.map(|o| o.unwrap_or(usize::MAX));
    let mut w = kept;
    let mut map = idx;
    for i in (first_out..n).rev() {
        if status[i] == PointStatus::Kept {
            w -= 1;
            x.swap(w, i);
            z.swap(w, i);
            rho.swap(w, i);
            status[i] = status_of(aux[w]);
            for (m, &o) in map.iter_mut().zip(want.iter()) {
                if o == w {
                    *m = Some(i);
                }
            }
        }
    }
    for (st, &a) in status[..first_out].iter_mut().zip(aux.iter()) {
        *st = status_of(a);
    }
    map
}

/// Step 0 of [`Kernel::process`] with a region of interest: moves the points inside to
/// the front, in order, with their tags (a Lomuto partition from the first point outside;
/// the points outside end up behind them in the partition's order). Returns the number of
/// points inside.
#[inline(never)]
fn roi_partition(x: &mut [f32], z: &mut [f32], tag: &mut [u32], roi: Roi) -> usize {
    let n = tag.len();
    let (x, z) = (&mut x[..n], &mut z[..n]);
    let mut w = n;
    for i in 0..n {
        if !roi.contains(x[i], z[i]) {
            w = i;
            break;
        }
    }
    for i in w.saturating_add(1)..n {
        let (xi, zi) = (x[i], z[i]);
        if roi.contains(xi, zi) {
            let ti = tag[i];
            x[i] = x[w];
            z[i] = z[w];
            tag[i] = tag[w];
            x[w] = xi;
            z[w] = zi;
            tag[w] = ti;
            w += 1;
        }
    }
    w
}

/// Step 0 in a lean pass ([`Kernel::set_lean_rho`]): the points inside the region of
/// interest to the front, in order, with their tags, as [`roi_partition`] puts them; the
/// points outside are overwritten, not kept behind them (the packet does not carry them).
#[inline(never)]
fn roi_compact(x: &mut [f32], z: &mut [f32], tag: &mut [u32], roi: Roi) -> usize {
    let n = tag.len();
    let (x, z) = (&mut x[..n], &mut z[..n]);
    let mut w = 0;
    for i in 0..n {
        let (xi, zi) = (x[i], z[i]);
        if roi.contains(xi, zi) {
            x[w] = xi;
            z[w] = zi;
            tag[w] = tag[i];
            w += 1;
        }
    }
    w
}

/// Step 6 in a lean pass: the input indices of the compact indices `idx` (the kept points
/// in input order are the points with status [`PointStatus::Kept`]; points before
/// `first_out` never moved), without moving any point back.
#[inline(never)]
fn lean_unmap(
    status: &[PointStatus],
    first_out: usize,
    idx: [Option<usize>; 3],
) -> [Option<usize>; 3] {
    let want = idx.map(|o| o.unwrap_or(usize::MAX));
    let Some(last) = want.iter().copied().filter(|&o| o != usize::MAX).max() else {
        return idx;
    };
    let mut map = idx;
    let mut w = first_out;
    for (i, st) in status.iter().enumerate().skip(first_out) {
        if w > last {
            break;
        }
        if *st == PointStatus::Kept {
            for (m, &o) in map.iter_mut().zip(want.iter()) {
                if o == w {
                    *m = Some(i);
                }
            }
            w += 1;
        }
    }
    map
}

/// The status a kept point's `u8` in the working buffer stands for.
#[inline]
fn status_of(a: u8) -> PointStatus {
    if a == PointStatus::NoNeighbour as u8 {
        PointStatus::NoNeighbour
    } else {
        PointStatus::Kept
    }
}

#[cfg(all(test, feature = "libm"))]
mod tests;
