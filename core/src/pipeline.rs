//! [`Pipeline`]: the whole on-board path — bytes in, one [`ScanlineOutput`] per line out —
//! as the firmware's main loop and host-sim's in-process replay both run it.
//!
//! ```
//! use curbtrace_core::pipeline::{encode_output, Pipeline};
//! use curbtrace_core::wire::{PointRecord, StreamEncoder, MAX_PACKET_LEN};
//!
//! // A stream: one points packet holding a short flat line under the scanner.
//! let mut enc = StreamEncoder::new();
//! let points: Vec<PointRecord> = (0..50)
//!     .map(|i| PointRecord {
//!         dt_ns: 5_000 * i,
//!         x_m: -0.25 + 0.01 * i as f32,
//!         z_m: -2.0,
//!         intensity: 0,
//!         line_start: i == 0,
//!         tag: i,
//!     })
//!     .collect();
//! let mut bytes = vec![0u8; MAX_PACKET_LEN];
//! let n = enc.encode_points(1_000_000_000, &points, &mut bytes).unwrap();
//!
//! let mut p = Box::new(Pipeline::<4096, 2048>::new());
//! assert_eq!(p.write(&bytes[..n]), n);
//! let mut out_enc = StreamEncoder::new();
//! let mut packet = vec![0u8; 4 * MAX_PACKET_LEN];
//! let mut lines = 0;
//! p.finish(|out| {
//!     lines += 1;
//!     assert_eq!(out.status.len(), 50);
//!     assert!(encode_output(out, &mut out_enc, &mut packet).unwrap() > 0);
//! });
//! assert_eq!(lines, 1);
//! assert_eq!(p.counters().kernel_points, 50);
//! ```

use crate::kernel::{
    Kernel, KernelParams, OutputMode, ParamsError, PointStatus, ScanlineOutput, CONFIG_WORDS,
};
use crate::scanline::{Ingest, IngestCounters, IngestEvent, Line, SplitReason};
use crate::wire::{
    CandidatesRepr, EncodeError, OutputColumns, OutputHeaderRepr, OutputPointRepr, PointRecord,
    StreamEncoder,
};

/// Everything the pipeline counted: ingest's counters plus the kernel's, summed over lines,
/// and the config packets.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PipelineCounters {
    /// Bytes, packets, points and lines as ingest counted them.
    pub ingest: IngestCounters,
    /// Lines processed by the kernel.
    pub kernel_lines: u64,
    /// Points that entered the kernel (= the sum of the status counts below).
    pub kernel_points: u64,
    /// Points with status [`PointStatus::Kept`].
    pub kept: u64,
    /// Points with status [`PointStatus::Irregular`].
    pub irregular: u64,
    /// Points with status [`PointStatus::NoNeighbour`].
    pub no_neighbour: u64,
    /// Points with status [`PointStatus::NonFinite`].
    pub non_finite: u64,
    /// Points with status [`PointStatus::OutsideRoi`] (not processed by the kernel).
    pub outside_roi: u64,
    /// Peaks found.
    pub peaks: u64,
    /// Lines with a left candidate.
    pub left_candidates: u64,
    /// Lines with a right candidate.
    pub right_candidates: u64,
    /// Config packets whose parameters were applied.
    pub configs_applied: u64,
    /// Config packets rejected (parameters out of range); the previous ones stayed.
    pub configs_rejected: u64,
    /// Why the last config packet was rejected, if one was.
    pub last_config_error: Option<ParamsError>,
}

/// Ingest (ring, parser, assembly) and the kernel, for lines of up to `N` points and a ring
/// of `RING` bytes. Starts with [`KernelParams::DEFAULT`]; a config packet in the stream
/// reconfigures the kernel and the assembler from the next line on.
pub struct Pipeline<const RING: usize, const N: usize> {
    ingest: Ingest<RING, N>,
    kernel: Kernel<N>,
    c: PipelineCounters,
    /// The assembler still has to be given the kernel's split parameters (see
    /// [`Pipeline::new`]).
    fresh: bool,
}

impl<const RING: usize, const N: usize> Pipeline<RING, N> {
    /// A pipeline with the default parameters.
    ///
    /// `const`, so that the pipeline can be a `static` (the firmware's ~80 KiB then never
    /// pass through its stack). The assembler takes the parameters' split rules on the first
    /// [`Pipeline::run`], before it sees a point.
    pub const fn new() -> Self {
        Self {
            ingest: Ingest::new(),
            kernel: Kernel::new(KernelParams::DEFAULT),
            c: Self::new_counters(),
            fresh: true,
        }
    }

    /// Every counter zero.
    const fn new_counters() -> PipelineCounters {
        PipelineCounters {
            ingest: IngestCounters::ZERO,
            kernel_lines: 0,
            kernel_points: 0,
            kept: 0,
            irregular: 0,
            no_neighbour: 0,
            non_finite: 0,
            outside_roi: 0,
            peaks: 0,
            left_candidates: 0,
            right_candidates: 0,
            configs_applied: 0,
            configs_rejected: 0,
            last_config_error: None,
        }
    }

    /// The pipeline [`Pipeline::new`] gives, without rewriting its buffers (a few hundred KB
    /// that a new pipeline zeroes): the host's replay restarts one pipeline per thread for
    /// every chunk of points. Every buffer entry a stream reads is written by that stream
    /// first, so a restarted pipeline gives what a new one does (tested).
    pub fn restart(&mut self) {
        let Self {
            ingest,
            kernel,
            c,
            fresh,
        } = self;
        ingest.restart();
        kernel.restart(KernelParams::DEFAULT);
        *c = Self::new_counters();
        *fresh = true;
    }

    /// The ring's free space, for a DMA engine or a `read()` call to fill in place;
    /// follow with [`Pipeline::commit`].
    pub fn free_slices_mut(&mut self) -> (&mut [u8], &mut [u8]) {
        self.ingest.free_slices_mut()
    }

    /// Marks `n` bytes written through [`Pipeline::free_slices_mut`] as received; returns
    /// the bytes that fit (the rest is counted as dropped).
    pub fn commit(&mut self, n: usize) -> usize {
        self.ingest.commit(n)
    }

    /// Offers bytes; returns how many were accepted (the rest is counted as dropped).
    pub fn write(&mut self, bytes: &[u8]) -> usize {
        self.ingest.write(bytes)
    }

    /// Processes every complete line in the ring, calling `on_line` with each result; a
    /// config packet reconfigures the kernel (bad ones are counted, the old parameters stay).
    pub fn run(&mut self, mut on_line: impl FnMut(&ScanlineOutput<'_>)) {
        self.settle_split();
        loop {
            let Self {
                ingest, kernel, c, ..
            } = self;
            match ingest.poll() {
                None => break,
                Some(IngestEvent::Config(words)) => self.apply_config(&words),
                Some(IngestEvent::Line(line)) => process_line(kernel, c, line, &mut on_line),
            }
        }
    }

    /// Applies a config packet's parameter words: the kernel and the assembler take them
    /// (from the next line on); bad ones are counted and the old parameters stay.
    fn apply_config(&mut self, words: &[u32; CONFIG_WORDS]) {
        match KernelParams::from_words(words).and_then(|p| self.kernel.set_params(p).map(|()| p)) {
            Ok(p) => {
                self.ingest.set_split_params(p.split_params());
                self.c.configs_applied += 1;
            }
            Err(e) => {
                self.c.configs_rejected += 1;
                self.c.last_config_error = Some(e);
            }
        }
    }

    /// The assembler takes the kernel's split rules before it sees a point (see
    /// [`Pipeline::new`]).
    fn settle_split(&mut self) {
        if self.fresh {
            self.ingest
                .set_split_params(self.kernel.params().split_params());
            self.fresh = false;
        }
    }

    /// A config packet's words given directly, without their packet: the line being
    /// assembled is completed and processed first, then the words apply as
    /// [`Pipeline::run`] applies a config packet's. With [`Pipeline::push_point`] this is
    /// the core fed by a caller that holds decoded points (host-sim's replay), skipping
    /// the bytes, the CRC and the parse; the assembler, the split rules and the kernel are
    /// the same code, so the lines and their output are too.
    pub fn push_config(
        &mut self,
        words: &[u32; CONFIG_WORDS],
        mut on_line: impl FnMut(&ScanlineOutput<'_>),
    ) {
        self.settle_split();
        let Self {
            ingest, kernel, c, ..
        } = self;
        if let Some(line) = ingest.close_line(SplitReason::Config) {
            process_line(kernel, c, line, &mut on_line);
        }
        self.apply_config(words);
    }

    /// One point given directly, at absolute time `t_ns`, as ingest hands a parsed record
    /// of a points packet to the assembler (a non-finite x′ or z′ is counted and dropped,
    /// as ingest drops such a record); a line it completes is processed and given to
    /// `on_line` first. `p.dt_ns` is not read. See [`Pipeline::push_config`].
    #[inline]
    pub fn push_point(
        &mut self,
        t_ns: u64,
        p: &PointRecord,
        mut on_line: impl FnMut(&ScanlineOutput<'_>),
    ) {
        self.settle_split();
        let Self {
            ingest, kernel, c, ..
        } = self;
        while let Some(line) = ingest.offer_point(t_ns, p) {
            process_line(kernel, c, line, &mut on_line);
        }
    }

    /// End of stream: the partial last line is completed and processed like the others.
    pub fn finish(&mut self, on_line: impl FnMut(&ScanlineOutput<'_>)) {
        self.ingest.finish();
        self.run(on_line);
    }

    /// The counters so far.
    pub fn counters(&self) -> PipelineCounters {
        PipelineCounters {
            ingest: self.ingest.counters(),
            ..self.c
        }
    }

    /// The kernel parameters in force.
    pub fn params(&self) -> &KernelParams {
        self.kernel.params()
    }

    /// [`Kernel::set_lean_rho`]: in candidates mode, ρ only where the candidates packet
    /// can depend on it (the packets are the same; the firmware turns it on).
    pub fn set_lean_rho(&mut self, on: bool) {
        self.kernel.set_lean_rho(on);
    }
}

/// Runs the kernel on a complete line and counts its output.
fn process_line<const N: usize>(
    kernel: &mut Kernel<N>,
    c: &mut PipelineCounters,
    line: &mut Line<N>,
    on_line: &mut impl FnMut(&ScanlineOutput<'_>),
) {
    let out = kernel.process(line);
    let k = out.counters;
    c.kernel_lines += 1;
    c.kernel_points += u64::from(k.points_in);
    c.kept += u64::from(k.kept);
    c.irregular += u64::from(k.irregular);
    c.no_neighbour += u64::from(k.no_neighbour);
    c.non_finite += u64::from(k.non_finite);
    c.outside_roi += u64::from(k.outside_roi);
    c.peaks += u64::from(k.peaks);
    c.left_candidates += u64::from(out.left.is_some());
    c.right_candidates += u64::from(out.right.is_some());
    on_line(&out);
}

impl<const RING: usize, const N: usize> Default for Pipeline<RING, N> {
    fn default() -> Self {
        Self::new()
    }
}

/// Writes what the line's output mode asks for into `buf` (see `docs/wire-format.md`):
/// in [`OutputMode::Candidates`] the line's one candidates packet
/// ([`encode_candidates`]), otherwise all its output packets back to back; returns the
/// bytes written. `buf` needs
/// `wire::output_packet_len` of each fragment — at most
/// ⌈len / `MAX_OUTPUT_POINTS_PER_PACKET`⌉ · `MAX_PACKET_LEN` bytes. The header is
/// [`output_header`]'s and point `i` is [`output_point`]'s; each packet is
/// [`encode_output_fragment`]'s (a sender short of RAM writes one packet at a time with
/// it, as the firmware does: the same bytes). On an error, packets already written stay
/// written (and have used their sequence numbers).
pub fn encode_output(
    out: &ScanlineOutput<'_>,
    enc: &mut StreamEncoder,
    buf: &mut [u8],
) -> Result<usize, EncodeError> {
    if out.output_mode == OutputMode::Candidates {
        return encode_candidates(out, enc, buf);
    }
    let header = output_header(out)?;
    let mut at = 0usize;
    for k in 0..header.fragments() {
        let first = OutputHeaderRepr::fragment_first(k)?;
        let dst = buf.get_mut(at..).unwrap_or(&mut []);
        at += encode_output_fragment(out, &header, first, enc, dst)?;
    }
    Ok(at)
}

/// Writes the output packet of a line whose points start at `first` (0, then steps of
/// `MAX_OUTPUT_POINTS_PER_PACKET`), `header` being [`output_header`]'s; returns its
/// length. The bytes are those of `StreamEncoder::encode_output_fragment` with
/// [`output_point`], written by the encoder's tight loop over the line's columns
/// (`StreamEncoder::encode_output_columns`): points it cannot take directly (status
/// [`PointStatus::NonFinite`], non-finite or large values) go through [`output_point`],
/// errors included.
pub fn encode_output_fragment(
    out: &ScanlineOutput<'_>,
    header: &OutputHeaderRepr,
    first: u16,
    enc: &mut StreamEncoder,
    buf: &mut [u8],
) -> Result<usize, EncodeError> {
    let cols = OutputColumns {
        tag: out.tag,
        x_m: out.x_m,
        z_m: out.z_m,
        rho_deg: out.rho_deg,
        status: out.status,
    };
    // NonFinite points are sent at x′ = z′ = 0 by `output_point`: not the fast path's.
    let wire_status = |s: PointStatus| (s != PointStatus::NonFinite).then_some(s as u8);
    enc.encode_output_columns(
        header,
        first,
        &cols,
        wire_status,
        |i| output_point(out, i),
        buf,
    )
}

/// Writes the line's candidates packet (kind 4, wire version 2): its header as
/// [`output_header`] gives it and the output records ([`output_point`]) of its nadir and
/// seed candidates. Returns the packet length.
pub fn encode_candidates(
    out: &ScanlineOutput<'_>,
    enc: &mut StreamEncoder,
    buf: &mut [u8],
) -> Result<usize, EncodeError> {
    enc.encode_candidates(&candidates_repr(out)?, buf)
}

/// The candidates packet of a line (see [`encode_candidates`]).
pub fn candidates_repr(out: &ScanlineOutput<'_>) -> Result<CandidatesRepr, EncodeError> {
    let header = output_header(out)?;
    let rec = |i: Option<u16>| i.map(|i| output_point(out, usize::from(i))).transpose();
    Ok(CandidatesRepr {
        header,
        nadir: rec(out.nadir)?,
        left: rec(out.left)?,
        right: rec(out.right)?,
    })
}

/// The wire header of a line's output packets. Counters above 65 535 saturate in the
/// header's 16-bit fields.
pub fn output_header(out: &ScanlineOutput<'_>) -> Result<OutputHeaderRepr, EncodeError> {
    let sat = |v: u32| u16::try_from(v).unwrap_or(u16::MAX);
    let line_len = u16::try_from(out.status.len()).map_err(|_| EncodeError::TooManyPoints {
        count: out.status.len(),
        max: usize::from(u16::MAX),
    })?;
    Ok(OutputHeaderRepr {
        index: out.index,
        start_time_ns: out.start_time_ns,
        params_hash: out.params_hash,
        truncated: out.truncated,
        line_len,
        first: 0,
        nadir: out.nadir,
        left: out.left,
        right: out.right,
        kept: sat(out.counters.kept),
        irregular: sat(out.counters.irregular),
        no_neighbour: sat(out.counters.no_neighbour),
        peaks: sat(out.counters.peaks),
        outside: sat(out.counters.outside_roi),
    })
}

/// Output point `i` of a line. A non-finite point (status [`PointStatus::NonFinite`],
/// which ingest normally drops before the kernel) is sent at x′ = z′ = 0 with its status,
/// so the line still encodes; so is a point outside the region of interest
/// ([`PointStatus::OutsideRoi`]) whose raw coordinates are beyond ±`MAX_COORD_M` (the
/// kernel would have set it aside as non-finite).
pub fn output_point(out: &ScanlineOutput<'_>, i: usize) -> Result<OutputPointRepr, EncodeError> {
    let status = *out
        .status
        .get(i)
        .ok_or(EncodeError::OutOfRange { index: i })?;
    let get = |s: &[f32]| s.get(i).copied().unwrap_or(0.0);
    let (x, z) = (get(out.x_m), get(out.z_m));
    let lim = crate::kernel::bend::MAX_COORD_M;
    let (x, z) = if status == PointStatus::NonFinite
        || (status == PointStatus::OutsideRoi && !(x.abs() <= lim && z.abs() <= lim))
    {
        (0.0, 0.0)
    } else {
        (x, z)
    };
    let tag = out.tag.get(i).copied().unwrap_or(0);
    OutputPointRepr::from_f32(tag, x, z, get(out.rho_deg), status as u8, i)
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::wire::{
        scan, Packet, PacketKind, PointRecord, Scan, MAX_OUTPUT_POINTS_PER_PACKET, MAX_PACKET_LEN,
        MAX_POINTS_PER_PACKET,
    };
    use std::vec::Vec;

    const RING: usize = 16384;
    const N: usize = 4096;

    /// A stream of `lines` flat lines of 300 points with a 150 mm step at x′ = +1 m, flags set.
    fn stream(enc: &mut StreamEncoder, lines: u32, out: &mut Vec<u8>) {
        let mut buf = std::vec![0u8; MAX_PACKET_LEN];
        for l in 0..lines {
            let pts: Vec<PointRecord> = (0..300u32)
                .map(|i| {
                    let x = -1.0 + 0.01 * i as f32;
                    let (x, z) = if i < 200 {
                        (x, -2.0)
                    } else if i < 215 {
                        (1.0, -2.0 + 0.01 * (i - 200) as f32)
                    } else {
                        (1.0 + 0.01 * (i - 215) as f32, -1.85)
                    };
                    PointRecord {
                        dt_ns: 1000 * i,
                        x_m: x,
                        z_m: z,
                        intensity: 0,
                        line_start: i == 0,
                        tag: l * 1000 + i,
                    }
                })
                .collect();
            for chunk in pts.chunks(MAX_POINTS_PER_PACKET) {
                let first = chunk[0].dt_ns;
                let rebased: Vec<PointRecord> = chunk
                    .iter()
                    .map(|p| PointRecord {
                        dt_ns: p.dt_ns - first,
                        ..*p
                    })
                    .collect();
                let base = 1_000_000_000 + u64::from(l) * 10_000_000 + u64::from(first);
                let n = enc.encode_points(base, &rebased, &mut buf).unwrap();
                out.extend_from_slice(&buf[..n]);
            }
        }
    }

    /// `new` is `const`: a pipeline can be a `static`, and it behaves as one built at run
    /// time (the derived values and the split rules are settled on first use).
    #[test]
    fn a_const_pipeline_runs_like_any_other() {
        static CONST: Pipeline<RING, 512> = Pipeline::new();
        assert_eq!(CONST.params(), &KernelParams::DEFAULT);
        assert_eq!(CONST.counters(), PipelineCounters::default());
        let mut enc = StreamEncoder::new();
        let mut bytes = Vec::new();
        stream(&mut enc, 2, &mut bytes);
        let mut p = std::boxed::Box::new(Pipeline::<RING, 512>::new());
        p.write(&bytes);
        let mut hashes = Vec::new();
        p.finish(|o| hashes.push((o.params_hash, o.left)));
        assert_eq!(hashes, [(KernelParams::DEFAULT.hash(), Some(200)); 2]);
        // The split rules in force are the parameters', applied before the first point.
        assert_eq!(
            p.ingest.split_params(),
            KernelParams::DEFAULT.split_params()
        );
    }

    /// A version-2 config packet (region of interest, candidates mode) is applied: the points
    /// outside are counted, the candidate is the same point as without a region, and each
    /// line's output is one candidates packet whose records are `output_point`'s.
    #[test]
    fn region_and_candidates_mode_from_a_version_2_config() {
        let params = KernelParams {
            roi_x_min_m: -0.505,
            roi_x_max_m: 2.0,
            roi_z_min_m: -2.5,
            roi_z_max_m: -1.5,
            output_mode: 1,
            ..KernelParams::DEFAULT
        };
        let mut enc = StreamEncoder::new();
        let mut buf = [0u8; MAX_PACKET_LEN];
        let n = enc.encode_config(&params.to_words(), &mut buf).unwrap();
        assert_eq!(
            buf[2], 2,
            "a config with version-2 words is a version-2 packet"
        );
        let mut bytes = buf[..n].to_vec();
        stream(&mut enc, 2, &mut bytes);
        let mut p = std::boxed::Box::new(Pipeline::<RING, N>::new());
        assert_eq!(p.write(&bytes), bytes.len());
        let mut lines = 0;
        p.finish(|o| {
            lines += 1;
            // Points at x′ < −0.5 (0..50) are outside; the toe (tag l·1000 + 200) is found.
            assert_eq!(o.counters.outside_roi, 50);
            assert_eq!(o.tag[usize::from(o.left.unwrap())] % 1000, 200);
            let mut pk = std::vec![0u8; MAX_PACKET_LEN];
            let len = encode_output(o, &mut StreamEncoder::new(), &mut pk).unwrap();
            let c = CandidatesRepr::parse(&Packet::new_checked(&pk[..len]).unwrap()).unwrap();
            assert_eq!(c.header.outside, 50);
            assert_eq!(
                c.left,
                Some(output_point(o, usize::from(o.left.unwrap())).unwrap())
            );
            assert_eq!(
                c.nadir.map(|r| r.tag),
                o.nadir.map(|i| o.tag[usize::from(i)])
            );
        });
        assert_eq!(lines, 2);
        let c = p.counters();
        assert_eq!((c.configs_applied, c.configs_rejected), (1, 0));
        assert_eq!(c.outside_roi, 100);
        assert_eq!(
            c.kept + c.irregular + c.no_neighbour + c.non_finite + c.outside_roi,
            600
        );
    }

    /// What a line's output holds, owned.
    type Seen = (
        u32,
        u64,
        u32,
        Vec<u32>,
        Vec<f32>,
        Vec<f32>,
        Vec<f32>,
        Vec<PointStatus>,
    );

    fn seen(o: &ScanlineOutput<'_>) -> Seen {
        (
            o.index,
            o.start_time_ns,
            o.params_hash,
            o.tag.to_vec(),
            o.x_m.to_vec(),
            o.z_m.to_vec(),
            o.rho_deg.to_vec(),
            o.status.to_vec(),
        )
    }

    /// A restarted pipeline runs a stream as a new one does, after a stream that left a
    /// config applied, a line half assembled and bytes in the ring.
    #[test]
    fn a_restarted_pipeline_runs_like_a_new_one() {
        let mut enc = StreamEncoder::new();
        let mut buf = [0u8; MAX_PACKET_LEN];
        let other = KernelParams {
            d_b_m: 0.05,
            ..KernelParams::DEFAULT
        };
        let n = enc.encode_config(&other.to_words(), &mut buf).unwrap();
        let mut before = buf[..n].to_vec();
        stream(&mut enc, 3, &mut before);
        let mut p = std::boxed::Box::new(Pipeline::<RING, N>::new());
        p.write(&before[..before.len() - 700]);
        p.run(|_| {});
        assert!(p.counters().ingest.points_pending > 0 && p.ingest.buffered() > 0);
        p.restart();
        let mut fresh = std::boxed::Box::new(Pipeline::<RING, N>::new());
        let mut after = Vec::new();
        stream(&mut StreamEncoder::new(), 2, &mut after);
        let mut outs = [Vec::new(), Vec::new()];
        for (q, out) in [&mut p, &mut fresh].into_iter().zip(&mut outs) {
            assert_eq!(q.write(&after), after.len());
            q.finish(|o| out.push(seen(o)));
        }
        assert_eq!(outs[0].len(), 2);
        assert_eq!(outs[0], outs[1]);
        assert_eq!(p.counters(), fresh.counters());
        assert_eq!(p.params(), fresh.params());
    }

    /// Points and config words given directly give the lines and the kernel's output of
    /// the same points sent as packets.
    #[test]
    fn points_given_directly_are_the_packets_lines() {
        let other = KernelParams {
            d_b_m: 0.05,
            ..KernelParams::DEFAULT
        };
        let mut enc = StreamEncoder::new();
        let mut buf = [0u8; MAX_PACKET_LEN];
        let n = enc.encode_config(&other.to_words(), &mut buf).unwrap();
        let mut bytes = buf[..n].to_vec();
        stream(&mut enc, 3, &mut bytes);
        let mut wire = std::boxed::Box::new(Pipeline::<RING, N>::new());
        let mut by_wire = Vec::new();
        for chunk in bytes.chunks(1000) {
            assert_eq!(wire.write(chunk), chunk.len());
            wire.run(|o| by_wire.push(seen(o)));
        }
        wire.finish(|o| by_wire.push(seen(o)));

        // The same records, parsed back out of the bytes, given one by one.
        let mut direct = std::boxed::Box::new(Pipeline::<RING, N>::new());
        let mut by_point = Vec::new();
        let mut at = 0;
        while at < bytes.len() {
            let Scan::Packet { len, .. } = scan(&bytes[at..], true) else {
                panic!("no packet at {at}");
            };
            let pk = Packet::new_checked(&bytes[at..at + len]).unwrap();
            if pk.kind() == Some(PacketKind::Config) {
                direct.push_config(&other.to_words(), |o| by_point.push(seen(o)));
            } else {
                let pts = crate::wire::PointsRepr::parse(&pk).unwrap();
                for r in &pts.points {
                    let t = pts.base_time_ns + u64::from(r.dt_ns);
                    direct.push_point(t, r, |o| by_point.push(seen(o)));
                }
            }
            at += len;
        }
        direct.finish(|o| by_point.push(seen(o)));
        assert_eq!(by_wire.len(), 3);
        assert_eq!(by_point, by_wire);
        let (d, w) = (direct.counters(), wire.counters());
        assert_eq!(
            (d.kernel_points, d.kept, d.configs_applied),
            (900, w.kept, 1)
        );
        assert_eq!(d.ingest.points_in_lines, w.ingest.points_in_lines);
        // A non-finite point is counted and dropped, as ingest drops such a record.
        let mut p = std::boxed::Box::new(Pipeline::<RING, N>::new());
        let bad = PointRecord {
            dt_ns: 0,
            x_m: f32::NAN,
            z_m: -2.0,
            intensity: 0,
            line_start: true,
            tag: 0,
        };
        p.push_point(1_000, &bad, |_| panic!("no line"));
        p.finish(|_| panic!("no line"));
        assert_eq!(p.counters().ingest.points_non_finite, 1);
    }

    #[test]
    fn lines_flow_through_and_every_point_is_counted() {
        let mut enc = StreamEncoder::new();
        let mut bytes = Vec::new();
        stream(&mut enc, 3, &mut bytes);
        let mut p = std::boxed::Box::new(Pipeline::<RING, N>::new());
        let mut seen = Vec::new();
        for chunk in bytes.chunks(1000) {
            assert_eq!(p.write(chunk), chunk.len());
            p.run(|o| seen.push((o.index, o.status.len(), o.left, o.tag[0])));
        }
        p.finish(|o| seen.push((o.index, o.status.len(), o.left, o.tag[0])));
        assert_eq!(seen.len(), 3);
        for (l, s) in seen.iter().enumerate() {
            // The toe is point 200 of each line.
            assert_eq!(*s, (l as u32, 300, Some(200), l as u32 * 1000));
        }
        let c = p.counters();
        assert_eq!(c.kernel_lines, 3);
        assert_eq!(c.kernel_points, 900);
        assert_eq!(c.ingest.points_in_lines, 900);
        assert_eq!(c.kept + c.irregular + c.no_neighbour + c.non_finite, 900);
        assert_eq!(c.left_candidates, 3);
        assert_eq!(c.right_candidates, 0);
    }

    #[test]
    fn config_packets_reconfigure_and_bad_ones_are_counted() {
        let mut enc = StreamEncoder::new();
        let mut bytes = Vec::new();
        let mut buf = [0u8; MAX_PACKET_LEN];
        // A good config: d_b = 0.05.
        let good = KernelParams {
            d_b_m: 0.05,
            ..KernelParams::DEFAULT
        };
        let n = enc.encode_config(&good.to_words(), &mut buf).unwrap();
        bytes.extend_from_slice(&buf[..n]);
        stream(&mut enc, 1, &mut bytes);
        // A bad one: NaN d_b.
        let mut w = good.to_words();
        w[0] = f32::NAN.to_bits();
        let n = enc.encode_config(&w, &mut buf).unwrap();
        bytes.extend_from_slice(&buf[..n]);
        stream(&mut enc, 1, &mut bytes);
        let mut p = std::boxed::Box::new(Pipeline::<RING, N>::new());
        let mut hashes = Vec::new();
        for chunk in bytes.chunks(4000) {
            p.write(chunk);
            p.run(|o| hashes.push(o.params_hash));
        }
        p.finish(|o| hashes.push(o.params_hash));
        assert_eq!(hashes, [good.hash(), good.hash()]);
        let c = p.counters();
        assert_eq!(c.configs_applied, 1);
        assert_eq!(c.configs_rejected, 1);
        assert_eq!(
            c.last_config_error,
            Some(ParamsError::OutOfRange {
                param: crate::kernel::Param::DBM
            })
        );
        assert_eq!(p.params().d_b_m, 0.05);
    }

    /// `encode_output` (the columns encoder) writes the bytes of the general encoder with
    /// `output_point`, also for a line with a NonFinite point, a non-finite ρ and values
    /// beyond the fast path.
    #[test]
    fn encode_output_is_the_general_encoder() {
        let mut enc = StreamEncoder::new();
        let mut bytes = Vec::new();
        stream(&mut enc, 1, &mut bytes);
        let mut p = std::boxed::Box::new(Pipeline::<RING, N>::new());
        p.write(&bytes);
        let mut checked = 0;
        p.finish(|o| {
            let mut x = o.x_m.to_vec();
            let mut rho = o.rho_deg.to_vec();
            let mut status = o.status.to_vec();
            status[5] = PointStatus::NonFinite;
            x[5] = f32::NAN;
            x[7] = 1500.0; // beyond the fast path's 1024 m, within the format's 2147 m
            rho[9] = -180.0;
            let o = ScanlineOutput {
                x_m: &x,
                rho_deg: &rho,
                status: &status,
                ..*o
            };
            let mut fast = std::vec![0u8; 8 * MAX_PACKET_LEN];
            let mut general = std::vec![0u8; 8 * MAX_PACKET_LEN];
            let n = encode_output(&o, &mut StreamEncoder::with_seq(9), &mut fast).unwrap();
            let h = output_header(&o).unwrap();
            let m = StreamEncoder::with_seq(9)
                .encode_output_line(&h, |i| output_point(&o, i), &mut general)
                .unwrap();
            assert_eq!(fast[..n], general[..m]);
            // A NaN ρ is an error with its index on both paths.
            let mut rho2 = rho.clone();
            rho2[11] = f32::NAN;
            let o = ScanlineOutput {
                rho_deg: &rho2,
                ..o
            };
            assert_eq!(
                encode_output(&o, &mut StreamEncoder::new(), &mut fast),
                Err(EncodeError::NonFinite { index: 11 })
            );
            assert_eq!(
                StreamEncoder::new().encode_output_line(&h, |i| output_point(&o, i), &mut general),
                Err(EncodeError::NonFinite { index: 11 })
            );
            checked += 1;
        });
        assert_eq!(checked, 1);
    }

    #[test]
    fn output_packets_carry_the_line() {
        let mut enc = StreamEncoder::new();
        let mut bytes = Vec::new();
        stream(&mut enc, 1, &mut bytes);
        let mut p = std::boxed::Box::new(Pipeline::<RING, N>::new());
        p.write(&bytes);
        let mut packets = std::vec![0u8; 8 * MAX_PACKET_LEN];
        let mut out_enc = StreamEncoder::new();
        let mut written = 0;
        let mut expect: Vec<(u32, f32, f32, f32, u8)> = Vec::new();
        p.finish(|o| {
            written = encode_output(o, &mut out_enc, &mut packets).unwrap();
            for i in 0..o.status.len() {
                expect.push((
                    o.tag[i],
                    o.x_m[i],
                    o.z_m[i],
                    o.rho_deg[i],
                    o.status[i] as u8,
                ));
            }
        });
        // Decode the packets back and compare point by point.
        let mut at = 0;
        let mut got = Vec::new();
        let mut fragments = 0;
        while at < written {
            let Scan::Packet { len, .. } = scan(&packets[at..written], true) else {
                panic!("no packet at {at}");
            };
            let pk = Packet::new_checked(&packets[at..at + len]).unwrap();
            assert_eq!(pk.kind(), Some(PacketKind::Output));
            let (h, pts) = OutputHeaderRepr::parse(&pk).unwrap();
            assert_eq!(h.line_len, 300);
            assert_eq!(h.left, Some(200));
            assert_eq!(h.params_hash, KernelParams::DEFAULT.hash());
            got.extend(pts);
            fragments += 1;
            at += len;
        }
        assert_eq!(fragments, 300usize.div_ceil(MAX_OUTPUT_POINTS_PER_PACKET));
        assert_eq!(got.len(), 300);
        for (g, e) in got.iter().zip(&expect) {
            assert_eq!(g.tag, e.0);
            assert!((g.x_m() - f64::from(e.1)).abs() < 1e-6);
            assert!((g.z_m() - f64::from(e.2)).abs() < 1e-6);
            assert!((g.rho_deg() - f64::from(e.3)).abs() <= 0.005 + 1e-9);
            assert_eq!(g.status, e.4);
        }
    }
}
