//! Tests of the output packets: golden bytes, fragmentation, rounding, and the columns
//! fast path against the general encoder.

extern crate std;
use super::super::{
    crc, EncodeError, Packet, StreamEncoder, MAX_OUTPUT_POINTS_PER_PACKET, MAX_PACKET_LEN,
};
use super::point::{scale_round, scale_round_fast};
use super::*;
use proptest::prelude::*;
use std::{vec, vec::Vec};

fn arb_point() -> impl Strategy<Value = OutputPointRepr> {
    (
        any::<u32>(),
        any::<i32>(),
        any::<i32>(),
        -17_999i16..=18_000,
        any::<u8>(),
    )
        .prop_map(|(tag, x_um, z_um, rho_cdeg, status)| OutputPointRepr {
            tag,
            x_um,
            z_um,
            rho_cdeg,
            status,
        })
}

fn header(line_len: u16) -> OutputHeaderRepr {
    OutputHeaderRepr {
        index: 12,
        start_time_ns: 1_000_000_000,
        params_hash: 0xDEAD_BEEF,
        truncated: 0,
        line_len,
        first: 0,
        nadir: line_len.checked_sub(1),
        left: None,
        right: Some(0).filter(|_| line_len > 0),
        kept: line_len,
        irregular: 0,
        no_neighbour: 0,
        peaks: 1,
        outside: 0,
    }
}

#[test]
fn scaling_rounds_half_away_and_wraps_minus_180() {
    let p = OutputPointRepr::from_f32(1, 1.2345675, -0.0000005, -180.0, 2, 0).unwrap();
    assert_eq!(p.x_um, 1_234_568); // f32(1.2345675) * 1e6 = 1234567.5 → away from zero
    assert_eq!(p.z_um, -1); // −0.5 µm → −1
    assert_eq!(p.rho_cdeg, 18_000);
    let p = OutputPointRepr::from_f32(1, -3.0, 0.0, 90.004, 0, 0).unwrap();
    assert_eq!((p.x_um, p.rho_cdeg), (-3_000_000, 9_000));
    assert_eq!(
        OutputPointRepr::from_f32(1, f32::NAN, 0.0, 0.0, 0, 4),
        Err(EncodeError::NonFinite { index: 4 })
    );
    assert_eq!(
        OutputPointRepr::from_f32(1, 3000.0, 0.0, 0.0, 0, 5),
        Err(EncodeError::OutOfRange { index: 5 })
    );
    assert_eq!(
        OutputPointRepr::from_f32(1, 0.0, 0.0, 180.01, 0, 6),
        Err(EncodeError::OutOfRange { index: 6 })
    );
}

#[test]
fn golden_output_packet() {
    let h = header(1);
    let p = OutputPointRepr {
        tag: 7,
        x_um: 1_500_000,
        z_um: -2_000_000,
        rho_cdeg: 9_000,
        status: 0,
    };
    let mut enc = StreamEncoder::with_seq(2);
    let mut out = [0u8; MAX_PACKET_LEN];
    let n = enc.encode_output(&h, &[p], &mut out).unwrap();
    #[rustfmt::skip]
    let golden: [u8; 72] = [
        0xA5, 0xC3, 0x01, 0x03, 0x48, 0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00,
        0x0C, 0x00, 0x00, 0x00, // index 12
        0x00, 0xCA, 0x9A, 0x3B, 0x00, 0x00, 0x00, 0x00, // start time 1e9 ns
        0xEF, 0xBE, 0xAD, 0xDE, // params hash
        0x00, 0x00, 0x00, 0x00, // truncated
        0x01, 0x00, 0x00, 0x00, // line_len 1, first 0
        0x00, 0x00, 0xFF, 0xFF, 0x00, 0x00, // nadir 0, left none, right 0
        0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x01, 0x00, // kept 1, irregular, no_neighbour, peaks 1
        0x00, 0x00, // reserved
        0x07, 0x00, 0x00, 0x00, 0x60, 0xE3, 0x16, 0x00, 0x80, 0x7B, 0xE1, 0xFF,
        0x28, 0x23, 0x00, 0x00, // point
        0, 0, 0, 0, // CRC, filled below
    ];
    let mut golden = golden;
    let crc = crc::crc32_bytewise(&golden[..68]);
    golden[68..].copy_from_slice(&crc.to_le_bytes());
    assert_eq!(&out[..n], &golden[..]);
    let pk = Packet::new_checked(&golden[..]).unwrap();
    let (hh, pts) = OutputHeaderRepr::parse(&pk).unwrap();
    assert_eq!(hh, h);
    let pts: heapless::Vec<_, 4> = pts.collect();
    assert_eq!(&pts[..], &[p]);
    assert_eq!(pts[0].rho_deg(), 90.0);
}

#[test]
fn fragmentation_of_a_long_line() {
    // 2000 points → ⌈2000/88⌉ = 23 packets, the last with 2000 − 22·88 = 64 points.
    let h = header(2000);
    let mut enc = StreamEncoder::new();
    let mut buf = [0u8; 40_000];
    let n = enc
        .encode_output_line(
            &h,
            |i| {
                OutputPointRepr::from_f32(
                    u32::try_from(i).unwrap(),
                    i as f32 * 0.01,
                    -2.0,
                    0.0,
                    0,
                    i,
                )
            },
            &mut buf,
        )
        .unwrap();
    assert_eq!(MAX_OUTPUT_POINTS_PER_PACKET, 88);
    assert_eq!(h.fragments(), 23);
    assert_eq!(n, 22 * output_packet_len(88) + output_packet_len(64));
    let mut at = 0;
    let mut next_tag = 0u32;
    let mut packets = 0;
    while at < n {
        let pk = Packet::new_checked(&buf[at..n]).unwrap();
        assert_eq!(pk.seq(), packets);
        assert!(pk.length() <= MAX_PACKET_LEN);
        let (hh, pts) = OutputHeaderRepr::parse(&pk).unwrap();
        assert_eq!(usize::from(hh.first), usize::try_from(next_tag).unwrap());
        for p in pts {
            assert_eq!(p.tag, next_tag);
            assert_eq!(p.x_um, (next_tag as f32 * 0.01 * 1e6).round() as i32);
            next_tag += 1;
        }
        at += pk.length();
        packets += 1;
    }
    assert_eq!((next_tag, packets), (2000, 23));
    // An empty line is one packet with no points.
    let n = enc
        .encode_output_line(&header(0), |_| unreachable!(), &mut buf)
        .unwrap();
    assert_eq!(n, output_packet_len(0));
    let pk = Packet::new_checked(&buf[..n]).unwrap();
    let (hh, mut pts) = OutputHeaderRepr::parse(&pk).unwrap();
    assert_eq!((hh.line_len, pts.next()), (0, None));
}

#[test]
fn encoder_rejects_bad_headers() {
    let mut enc = StreamEncoder::new();
    let mut buf = [0u8; MAX_PACKET_LEN];
    let mut h = header(3);
    h.left = Some(3);
    assert!(enc
        .encode_output(&h, &[OutputPointRepr::default(); 3], &mut buf)
        .is_err());
    let h = header(3);
    // Wrong number of points for the fragment.
    assert!(enc
        .encode_output(&h, &[OutputPointRepr::default(); 2], &mut buf)
        .is_err());
    assert_eq!(
        enc.seq(),
        0,
        "failed encodes do not consume sequence numbers"
    );
}

#[test]
fn fast_rounding_is_the_general_one() {
    // Halves, neighbours of halves, the 2^30 edge, huge, non-finite, signed zeros.
    let mut vals = std::vec![
        0.0f32,
        -0.0,
        0.5e-6,
        -0.5e-6,
        1.5e-6,
        -2.5e-6,
        1e-45,
        -1e-45,
        0.004_999_999,
        0.005,
        -0.005,
        179.995,
        -179.995,
        180.0,
        -180.0,
        180.004,
        3000.0,
        f32::MAX,
        f32::MIN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::NAN,
    ];
    // Around 2^30 µm (the fast path's edge) and 2^31 µm (the i32 edge), ± a few ulps.
    for edge in [1_073_741_824.0f32 * 1e-6, 2_147_483_648.0 * 1e-6] {
        for k in 0..8u32 {
            let up = f32::from_bits(edge.to_bits() + k);
            let down = f32::from_bits(edge.to_bits() - k);
            vals.extend([up, down, -up, -down]);
        }
    }
    let mut r = 99u64;
    for _ in 0..200_000 {
        r = r
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let v = f32::from_bits((r >> 32) as u32);
        vals.push(v);
        vals.push(f32::from_bits(((r >> 40) as u32 & 0x00FF_FFFF) | 0x4000_0000) - 3.0);
        // k + 0.5 µm exactly and one ulp either side.
        let h = ((r >> 44) as i32 - (1 << 19)) as f32 + 0.5;
        for w in [
            h,
            f32::from_bits(h.to_bits() + 1),
            f32::from_bits(h.to_bits() - 1),
        ] {
            vals.push(w * 1e-6);
            vals.push(w * 1e-2);
        }
    }
    for v in vals {
        for (scale, lo, hi) in [(1e6f32, i32::MIN, i32::MAX), (100.0, -18_000, 18_000)] {
            let general = scale_round(v, scale, lo, hi);
            if let Some(f) = scale_round_fast(v, 2.0 * scale) {
                let f = (lo..=hi).contains(&f).then_some(f);
                assert_eq!(f, general, "{v:e} × {scale}");
            } else {
                assert!(!(v * scale).is_finite() || (v * scale).abs() >= 1073741824.0);
            }
        }
    }
}

/// A value for the columns test: ordinary, on a rounding half, at the fast path's edges
/// (1024 m, ±180°), beyond them, huge, non-finite or any bit pattern.
fn arb_value() -> impl Strategy<Value = f32> {
    prop_oneof![
        4 => -3.0f32..3.0,
        2 => -200.0f32..200.0,
        1 => (-2_000_000i32..2_000_000).prop_map(|k| (k as f32 + 0.5) * 1e-6),
        1 => (-36_000i32..36_000).prop_map(|k| (k as f32 + 0.5) * 0.005),
        1 => prop_oneof![
            Just(180.0f32), Just(-180.0), Just(179.995), Just(-179.995), Just(-179.997),
            Just(180.004), Just(-180.004), Just(1024.0), Just(-1024.0),
            Just(f32::from_bits(1024f32.to_bits() - 1)), Just(2147.48), Just(3000.0),
            Just(f32::MAX), Just(f32::NAN), Just(f32::INFINITY), Just(f32::NEG_INFINITY),
            Just(0.0), Just(-0.0),
        ],
        1 => any::<u32>().prop_map(f32::from_bits),
    ]
}

/// The general path the columns encoder must equal: `from_f32` on each point, status 3
/// (the pipeline's NonFinite) sent at x′ = z′ = 0.
fn general_point(
    tag: &[u32],
    x: &[f32],
    z: &[f32],
    rho: &[f32],
    st: &[u8],
    i: usize,
) -> Result<OutputPointRepr, EncodeError> {
    let g = |s: &[f32]| s.get(i).copied().unwrap_or(0.0);
    let s = *st.get(i).ok_or(EncodeError::OutOfRange { index: i })?;
    let (xv, zv) = if s == 3 { (0.0, 0.0) } else { (g(x), g(z)) };
    OutputPointRepr::from_f32(tag.get(i).copied().unwrap_or(0), xv, zv, g(rho), s, i)
}

#[test]
fn columns_fast_path_edges() {
    // Points on the fast path's edges, one per line, against the general path.
    let edges = [
        (0.0f32, 0.0f32, -180.0f32),
        (0.0, 0.0, 180.0),
        (0.0, 0.0, -179.997), // rounds to −18 000 → +18 000
        (0.0, 0.0, -179.99),  // the fast path's lower edge and its neighbours
        (0.0, 0.0, f32::from_bits((-179.99f32).to_bits() - 1)),
        (0.0, 0.0, f32::from_bits((-179.99f32).to_bits() + 1)),
        (0.0, 0.0, -179.995), // −17 999.5 centidegrees → −18 000 → +18 000
        (0.0, 0.0, f32::from_bits(180f32.to_bits() - 1)),
        (0.0, 0.0, f32::from_bits(180f32.to_bits() + 1)),
        (f32::from_bits(1024f32.to_bits() - 1), -1023.9999, 0.0),
        (1024.0, 0.0, 0.0),
        (-1024.0, 0.0, 0.0),
        (2147.4836, 0.0, 0.0),
        (1.2345675, -0.0000005, 0.004_999_999),
        (f32::NAN, 0.0, 0.0),
        (0.0, f32::INFINITY, 0.0),
        (0.0, 0.0, f32::NEG_INFINITY),
    ];
    for (k, &(x, z, r)) in edges.iter().enumerate() {
        for st in 0u8..=4 {
            let cols = OutputColumns {
                tag: &[k as u32][..],
                x_m: &[x][..],
                z_m: &[z][..],
                rho_deg: &[r][..],
                status: &[st][..],
            };
            let h = header(1);
            let mut a = [0u8; MAX_PACKET_LEN];
            let mut b = [0u8; MAX_PACKET_LEN];
            let ra = StreamEncoder::new().encode_output_fragment(
                &h,
                0,
                |i| general_point(cols.tag, cols.x_m, cols.z_m, cols.rho_deg, cols.status, i),
                &mut a,
            );
            let rb = StreamEncoder::new().encode_output_columns(
                &h,
                0,
                &cols,
                |s: u8| (s != 3).then_some(s),
                |i| general_point(cols.tag, cols.x_m, cols.z_m, cols.rho_deg, cols.status, i),
                &mut b,
            );
            assert_eq!(ra, rb, "{x:e} {z:e} {r:e} status {st}");
            if let Ok(n) = ra {
                assert_eq!(a[..n], b[..n], "{x:e} {z:e} {r:e} status {st}");
            }
        }
    }
}

proptest! {
    /// The columns encoder (fast path, fused CRC) writes the bytes of the general
    /// encoder, or fails with the same error, for every fragment of a random line with
    /// NaN, ±inf, huge values, ρ = ±180°, every status and short columns.
    #[test]
    fn columns_equal_general(
        pts in proptest::collection::vec(
            (any::<u32>(), arb_value(), arb_value(), arb_value(), 0u8..=4), 0..200),
        short in proptest::option::of((0usize..5, 0usize..200)),
        seq in any::<u32>(),
    ) {
        let tag: Vec<u32> = pts.iter().map(|p| p.0).collect();
        let mut x: Vec<f32> = pts.iter().map(|p| p.1).collect();
        let mut z: Vec<f32> = pts.iter().map(|p| p.2).collect();
        let rho: Vec<f32> = pts.iter().map(|p| p.3).collect();
        let st: Vec<u8> = pts.iter().map(|p| p.4).collect();
        // Sometimes one column is cut short: every point then takes the general path,
        // which reads the missing values as 0.
        if let Some((col, at)) = short {
            match col {
                0 => x.truncate(at),
                1 => z.truncate(at),
                _ => {}
            }
        }
        let cols = OutputColumns { tag: &tag[..], x_m: &x[..], z_m: &z[..], rho_deg: &rho[..], status: &st[..] };
        let h = header(u16::try_from(pts.len()).unwrap());
        for k in 0..h.fragments() {
            let first = u16::try_from(k * MAX_OUTPUT_POINTS_PER_PACKET).unwrap();
            let mut a = vec![0u8; MAX_PACKET_LEN];
            let mut b = vec![0u8; MAX_PACKET_LEN];
            let mut ea = StreamEncoder::with_seq(seq);
            let mut eb = StreamEncoder::with_seq(seq);
            let gp = |i| general_point(&tag, &x, &z, &rho, &st, i);
            let ra = ea.encode_output_fragment(&h, first, gp, &mut a);
            let rb = eb.encode_output_columns(&h, first, &cols, |s: u8| (s != 3).then_some(s), gp, &mut b);
            prop_assert_eq!(ra, rb);
            prop_assert_eq!(ea.seq(), eb.seq());
            if let Ok(n) = ra {
                prop_assert_eq!(&a[..n], &b[..n]);
            }
        }
    }

    /// parse ∘ emit is the identity on reprs (every fragment of a random line).
    #[test]
    fn output_roundtrip(pts in proptest::collection::vec(arb_point(), 0..300),
                        index in any::<u32>(), t in any::<u64>(), hash in any::<u32>(),
                        trunc in any::<u32>(), nadir in any::<u16>(), left in any::<u16>(),
                        counts in proptest::array::uniform4(any::<u16>())) {
        let line_len = u16::try_from(pts.len()).unwrap();
        let pick = |v: u16| if line_len == 0 || v.is_multiple_of(3) { None } else { Some(v % line_len) };
        let h = OutputHeaderRepr {
            index, start_time_ns: t, params_hash: hash, truncated: trunc, line_len, first: 0,
            nadir: pick(nadir), left: pick(left), right: pick(nadir.wrapping_add(left)),
            kept: counts[0], irregular: counts[1], no_neighbour: counts[2], peaks: counts[3],
            outside: counts[0] / 2,
        };
        let mut enc = StreamEncoder::new();
        let mut buf = vec![0u8; 8000];
        let n = enc.encode_output_line(&h, |i| Ok(pts[i]), &mut buf).unwrap();
        let mut at = 0;
        let mut got = Vec::new();
        while at < n {
            let pk = Packet::new_checked(&buf[at..n]).unwrap();
            let (hh, ps) = OutputHeaderRepr::parse(&pk).unwrap();
            prop_assert_eq!(hh, OutputHeaderRepr { first: hh.first, ..h });
            prop_assert_eq!(usize::from(hh.first), got.len());
            got.extend(ps);
            at += pk.length();
        }
        prop_assert_eq!(got, pts);
    }

    /// emit ∘ parse is the identity on canonical bytes.
    #[test]
    fn output_canonical(pts in proptest::collection::vec(arb_point(), 1..5), at in 0usize..200, val in any::<u8>()) {
        let h = header(u16::try_from(pts.len()).unwrap());
        let mut enc = StreamEncoder::new();
        let mut b = [0u8; MAX_PACKET_LEN];
        let n = enc.encode_output(&h, &pts, &mut b).unwrap();
        let at = at % (n - 4);
        b[at] = val;
        let crc = crc::crc32(&b[..n - 4]);
        b[n - 4..n].copy_from_slice(&crc.to_le_bytes());
        let pk = Packet::new_unchecked(&b[..n]);
        if let Ok((hh, ps)) = OutputHeaderRepr::parse(&pk) {
            let ps: Vec<_> = ps.collect();
            let mut again = [0u8; MAX_PACKET_LEN];
            let mut e2 = StreamEncoder::with_seq(pk.seq());
            let m = e2.encode_output(&hh, &ps, &mut again).unwrap();
            prop_assert_eq!(&again[..m], &b[..n]);
        }
    }
}

/// A candidates packet: version 2, 104 bytes, parse ∘ emit is the identity, an absent
/// record is 16 zero bytes, and the packet labelled version 1 is refused.
#[test]
fn candidates_packet_round_trips_as_version_2() {
    use crate::wire::{CandidatesRepr, PacketKind, CANDIDATES_PACKET_LEN};
    let p = |tag: u32, x: f32| OutputPointRepr::from_f32(tag, x, -2.0, 91.5, 0, 0).unwrap();
    let header = OutputHeaderRepr {
        nadir: Some(3),
        left: Some(7),
        right: None,
        outside: 1200,
        ..header(10)
    };
    let c = CandidatesRepr {
        header,
        nadir: Some(p(3, 0.01)),
        left: Some(p(7, 2.4)),
        right: None,
    };
    let mut buf = [0u8; 200];
    let n = StreamEncoder::with_seq(5)
        .encode_candidates(&c, &mut buf)
        .unwrap();
    assert_eq!((n, CANDIDATES_PACKET_LEN), (104, 104));
    let pk = Packet::new_checked(&buf[..n]).unwrap();
    assert_eq!((pk.version(), pk.kind()), (2, Some(PacketKind::Candidates)));
    assert_eq!(CandidatesRepr::parse(&pk), Ok(c));
    assert!(buf[n - 4 - 16..n - 4].iter().all(|&b| b == 0));
    // A record without its index, or an index without its record, is refused.
    let bad = CandidatesRepr { right: c.left, ..c };
    assert!(StreamEncoder::new()
        .encode_candidates(&bad, &mut buf)
        .is_err());
    let bad = CandidatesRepr { left: None, ..c };
    assert!(StreamEncoder::new()
        .encode_candidates(&bad, &mut buf)
        .is_err());
    // Relabelled version 1 (CRC fixed): version 1 has no candidates packet.
    let mut v1 = buf[..n].to_vec();
    v1[2] = 1;
    let crc = crate::wire::crc::crc32(&v1[..n - 4]);
    v1[n - 4..].copy_from_slice(&crc.to_le_bytes());
    assert_eq!(
        CandidatesRepr::parse(&Packet::new_checked(&v1[..]).unwrap()),
        Err(crate::wire::Error::BadVersion { version: 1 })
    );
}

/// An output packet takes version 2 exactly when it counts points outside the region of
/// interest; a version-1 reader's packets (count 0) are unchanged.
#[test]
fn output_packets_take_version_2_only_for_the_outside_count() {
    let relabel = |b: &[u8], v: u8| {
        let mut b = b.to_vec();
        let n = b.len();
        b[2] = v;
        let crc = crate::wire::crc::crc32(&b[..n - 4]);
        b[n - 4..].copy_from_slice(&crc.to_le_bytes());
        b
    };
    let pt = OutputPointRepr::from_f32(1, 0.5, -2.0, 0.0, 4, 0).unwrap();
    let mut buf = [0u8; 200];
    for (outside, version) in [(0u16, 1u8), (9, 2)] {
        let h = OutputHeaderRepr {
            outside,
            ..header(1)
        };
        let n = StreamEncoder::new()
            .encode_output(&h, &[pt], &mut buf)
            .unwrap();
        let pk = Packet::new_checked(&buf[..n]).unwrap();
        assert_eq!(pk.version(), version);
        let (got, _) = OutputHeaderRepr::parse(&pk).unwrap();
        assert_eq!(got, h);
        let other = relabel(&buf[..n], 3 - version);
        let err = OutputHeaderRepr::parse(&Packet::new_checked(&other[..]).unwrap()).unwrap_err();
        if version == 2 {
            assert_eq!(err, crate::wire::Error::ReservedNotZero { offset: 50 });
        } else {
            assert_eq!(err, crate::wire::Error::BadVersion { version: 2 });
        }
    }
}
