//! Reading and comparing streams of output packets (`docs/wire-format.md`, "Output" and
//! "Candidates"), for `firmware/check.sh`: the firmware's output against the host core's.

use curbtrace_core::wire::{CandidatesRepr, OutputHeaderRepr, OutputPointRepr, Packet, PacketKind};

/// One scanline's result, reassembled from its output packets.
#[derive(Clone, Debug, PartialEq)]
pub struct LineResult {
    /// The line header (with `first` = 0).
    pub header: OutputHeaderRepr,
    /// Every point of the line, in order (of a candidates packet: the records it carries,
    /// nadir, left, right).
    pub points: Vec<OutputPointRepr>,
    /// The raw bytes of the line's packets, back to back.
    pub bytes: Vec<u8>,
}

/// Why a results stream could not be read.
#[derive(Debug, Clone, PartialEq)]
pub enum ReadError {
    /// The packet at `offset` is not a valid output packet.
    BadPacket {
        /// Byte offset of the packet in the stream.
        offset: usize,
        /// What the core's parser said.
        error: String,
    },
    /// A fragment at `offset` does not continue the line being reassembled.
    OutOfOrder {
        /// Byte offset of the packet in the stream.
        offset: usize,
    },
}

impl std::fmt::Display for ReadError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ReadError::BadPacket { offset, error } => {
                write!(f, "byte {offset}: not a valid output packet ({error})")
            }
            ReadError::OutOfOrder { offset } => {
                write!(f, "byte {offset}: fragment out of order")
            }
        }
    }
}

impl std::error::Error for ReadError {}

/// Splits a results stream (output or candidates packets back to back, nothing else) into
/// lines.
pub fn read_lines(stream: &[u8]) -> Result<Vec<LineResult>, ReadError> {
    let mut lines: Vec<LineResult> = Vec::new();
    let mut at = 0;
    while at < stream.len() {
        let bad = |error: String| ReadError::BadPacket { offset: at, error };
        let packet = Packet::new_checked(&stream[at..]).map_err(|e| bad(format!("{e:?}")))?;
        let len = packet.length();
        let packet = Packet::new_unchecked(&stream[at..at + len]);
        if packet.kind() == Some(PacketKind::Candidates) {
            let c = CandidatesRepr::parse(&packet).map_err(|e| bad(format!("{e:?}")))?;
            lines.push(LineResult {
                header: c.header,
                points: [c.nadir, c.left, c.right].into_iter().flatten().collect(),
                bytes: stream[at..at + len].to_vec(),
            });
            at += len;
            continue;
        }
        let (header, points) =
            OutputHeaderRepr::parse(&packet).map_err(|e| bad(format!("{e:?}")))?;
        if header.first == 0 {
            lines.push(LineResult {
                header: OutputHeaderRepr { first: 0, ..header },
                points: Vec::with_capacity(usize::from(header.line_len)),
                bytes: Vec::new(),
            });
        }
        let line = lines
            .last_mut()
            .filter(|l| {
                l.header == OutputHeaderRepr { first: 0, ..header }
                    && l.points.len() == usize::from(header.first)
            })
            .ok_or(ReadError::OutOfOrder { offset: at })?;
        line.points.extend(points);
        line.bytes.extend_from_slice(&stream[at..at + len]);
        at += len;
    }
    Ok(lines)
}

/// Exact comparison: how many scanlines differ in any byte (a line present in only one
/// stream differs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ExactComparison {
    /// Scanlines in the longer stream.
    pub scanlines: usize,
    /// Scanlines whose packets are not byte-identical.
    pub differ: usize,
}

/// Compares two results streams line by line, byte for byte.
pub fn compare_exact(a: &[LineResult], b: &[LineResult]) -> ExactComparison {
    let scanlines = a.len().max(b.len());
    let same = a.iter().zip(b).filter(|(x, y)| x.bytes == y.bytes).count();
    ExactComparison {
        scanlines,
        differ: scanlines - same,
    }
}

/// Approximate comparison (micromath against libm): ρ differences and candidate agreement.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct ApproxComparison {
    /// Scanlines in the longer stream.
    pub scanlines: usize,
    /// Scanlines present in both with the same number of points.
    pub scanlines_compared: usize,
    /// Points compared (in lines present in both).
    pub points: usize,
    /// Points whose status differs.
    pub status_differ: usize,
    /// Points kept in both whose ρ (centidegrees) differs.
    pub rho_differ: usize,
    /// Largest |Δρ| over points kept in both, degrees.
    pub rho_max_diff_deg: f64,
    /// Candidates (left and right seed candidates, nadir excluded) in the first stream.
    pub candidates: usize,
    /// Candidate slots (left/right per line) where the two streams disagree.
    pub candidates_differ: usize,
    /// Scanlines whose left and right candidates both agree.
    pub scanlines_agree: usize,
}

impl ApproxComparison {
    /// Share of scanlines whose candidates agree, percent (100 for no scanlines).
    pub fn agree_percent(&self) -> f64 {
        if self.scanlines == 0 {
            100.0
        } else {
            100.0 * self.scanlines_agree as f64 / self.scanlines as f64
        }
    }
}

/// Compares two results streams point by point and candidate by candidate.
pub fn compare_approx(a: &[LineResult], b: &[LineResult]) -> ApproxComparison {
    let mut c = ApproxComparison {
        scanlines: a.len().max(b.len()),
        ..Default::default()
    };
    for (x, y) in a.iter().zip(b) {
        let same_candidates = x.header.left == y.header.left && x.header.right == y.header.right;
        c.candidates +=
            usize::from(x.header.left.is_some()) + usize::from(x.header.right.is_some());
        c.candidates_differ += usize::from(x.header.left != y.header.left)
            + usize::from(x.header.right != y.header.right);
        if same_candidates {
            c.scanlines_agree += 1;
        }
        if x.points.len() != y.points.len() {
            continue;
        }
        c.scanlines_compared += 1;
        for (p, q) in x.points.iter().zip(&y.points) {
            c.points += 1;
            if p.status != q.status {
                c.status_differ += 1;
                continue;
            }
            // Status 0 is "kept" (kernel::PointStatus::Kept): only there is ρ meaningful.
            if p.status == 0 && p.rho_cdeg != q.rho_cdeg {
                c.rho_differ += 1;
                let d = (p.rho_deg() - q.rho_deg()).abs();
                // ρ wraps at ±180°.
                let d = d.min(360.0 - d);
                c.rho_max_diff_deg = c.rho_max_diff_deg.max(d);
            }
        }
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;
    use curbtrace_core::wire::{StreamEncoder, MAX_PACKET_LEN};

    fn header(index: u32, line_len: u16, left: Option<u16>) -> OutputHeaderRepr {
        OutputHeaderRepr {
            index,
            line_len,
            left,
            ..Default::default()
        }
    }

    fn encode(lines: &[(OutputHeaderRepr, Vec<OutputPointRepr>)]) -> Vec<u8> {
        let mut enc = StreamEncoder::new();
        let mut out = Vec::new();
        for (h, pts) in lines {
            let mut buf = vec![0u8; MAX_PACKET_LEN * (pts.len() / 64 + 1)];
            let n = enc
                .encode_output_line(h, |i| Ok(pts[i]), &mut buf)
                .expect("encodes");
            out.extend_from_slice(&buf[..n]);
        }
        out
    }

    fn pt(tag: u32, rho_cdeg: i16, status: u8) -> OutputPointRepr {
        OutputPointRepr {
            tag,
            x_um: 1000 * tag as i32,
            z_um: -5,
            rho_cdeg,
            status,
        }
    }

    #[test]
    fn reassembles_fragmented_lines() {
        // 130 points: fragments of 88 and 42 (MAX_OUTPUT_POINTS_PER_PACKET = 88).
        let pts: Vec<_> = (0..130).map(|i| pt(i, 0, 0)).collect();
        let stream = encode(&[
            (header(7, 130, Some(3)), pts.clone()),
            (header(8, 0, None), vec![]),
        ]);
        let lines = read_lines(&stream).expect("reads");
        assert_eq!(lines.len(), 2);
        assert_eq!(lines[0].header.index, 7);
        assert_eq!(lines[0].points, pts);
        assert_eq!(lines[1].points.len(), 0);
        assert_eq!(lines[0].bytes.len() + lines[1].bytes.len(), stream.len());
    }

    #[test]
    fn corrupt_stream_names_the_offset() {
        let mut stream = encode(&[(header(0, 1, None), vec![pt(1, 0, 0)])]);
        let last = stream.len() - 1;
        stream[last] ^= 1; // breaks the CRC
        assert!(matches!(
            read_lines(&stream),
            Err(ReadError::BadPacket { offset: 0, .. })
        ));
    }

    #[test]
    fn exact_counts_differing_and_missing_lines() {
        let a = read_lines(&encode(&[
            (header(0, 1, None), vec![pt(1, 10, 0)]),
            (header(1, 1, None), vec![pt(2, 10, 0)]),
            (header(2, 1, None), vec![pt(3, 10, 0)]),
        ]))
        .unwrap();
        let b = read_lines(&encode(&[
            (header(0, 1, None), vec![pt(1, 10, 0)]),
            (header(1, 1, None), vec![pt(2, 11, 0)]),
        ]))
        .unwrap();
        assert_eq!(
            compare_exact(&a, &a),
            ExactComparison {
                scanlines: 3,
                differ: 0
            }
        );
        assert_eq!(
            compare_exact(&a, &b),
            ExactComparison {
                scanlines: 3,
                differ: 2
            }
        );
    }

    #[test]
    fn approx_measures_rho_and_candidates() {
        let a = read_lines(&encode(&[
            (
                header(0, 2, Some(1)),
                vec![pt(1, 1000, 0), pt(2, 17_990, 0)],
            ),
            (header(1, 1, Some(0)), vec![pt(3, 0, 1)]),
        ]))
        .unwrap();
        let b = read_lines(&encode(&[
            (
                header(0, 2, Some(1)),
                vec![pt(1, 1016, 0), pt(2, -17_995, 0)],
            ),
            (header(1, 1, None), vec![pt(3, 0, 0)]),
        ]))
        .unwrap();
        let c = compare_approx(&a, &b);
        assert_eq!(c.scanlines, 2);
        assert_eq!(c.points, 3);
        assert_eq!(c.status_differ, 1);
        assert_eq!(c.rho_differ, 2);
        // 179.90° vs −179.95° are 0.15° apart across the wrap; 10.00° vs 10.16° are 0.16°.
        assert!(
            (c.rho_max_diff_deg - 0.16).abs() < 1e-9,
            "{}",
            c.rho_max_diff_deg
        );
        assert_eq!(c.candidates, 2);
        assert_eq!(c.candidates_differ, 1);
        assert_eq!(c.scanlines_agree, 1);
        assert!((c.agree_percent() - 50.0).abs() < 1e-12);
    }
}
