//! Arbitrary bytes into `Packet::new_checked` and the `parse` of every packet kind, and into
//! `scan`; whatever parses is emitted again and must parse to the same repr, byte for byte
//! (the format is canonical, `docs/wire-format.md`).
#![no_main]

use curbtrace_core::wire::{
    mark_link_checked, scan, ConfigRepr, OutputHeaderRepr, OutputPointRepr, Packet, PointsRepr,
    Scan, StreamEncoder, MAX_PACKET_LEN,
};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // The resynchronising scanner: whatever it says must be within the buffer.
    for at_end in [false, true] {
        match scan(data, at_end) {
            Scan::Empty => assert!(data.is_empty()),
            Scan::Packet { len } => {
                assert!(len <= data.len());
                // A packet found by scan has a valid envelope length and CRC, or is
                // link-checked with its CRC field zero.
                let p = Packet::new_checked(&data[..len]).expect("scan said packet");
                assert!(p.compute_crc() == p.crc() || (p.link_checked() && p.crc() == 0));
            }
            Scan::Garbage { len, .. } => assert!(len >= 1 && len <= data.len()),
            Scan::Incomplete => assert!(!at_end),
        }
    }

    let Ok(p) = Packet::new_checked(data) else {
        return;
    };
    // Accessors never panic, whatever the kind.
    let _ = (p.kind(), p.seq(), p.flags(), p.payload(), p.base_time_ns());
    for i in 0..=p.point_count() {
        let _ = p.point_bytes(i);
    }
    let len = p.length();
    let seq = p.seq();
    let mut out = [0u8; MAX_PACKET_LEN];
    // A link-checked packet is the CRC'd packet with its field zeroed and flagged.
    let lc = p.link_checked();

    if let Ok(r) = PointsRepr::parse(&p) {
        let n = r.emit(seq, &mut out).expect("a parsed points packet emits");
        if lc {
            mark_link_checked(&mut out[..n]);
        }
        assert_eq!(&out[..n], &data[..len]);
        let again = PointsRepr::parse(&Packet::new_checked(&out[..n]).unwrap()).unwrap();
        assert_eq!(again, r);
        // The stream encoder writes the same bytes.
        let mut enc = StreamEncoder::with_seq(seq).link_checked(lc);
        let mut out2 = [0u8; MAX_PACKET_LEN];
        let n2 = enc
            .encode_points(r.base_time_ns, &r.points, &mut out2)
            .unwrap();
        assert_eq!(&out2[..n2], &out[..n]);
    }
    if let Ok(r) = ConfigRepr::parse(&p) {
        let n = r.emit(seq, &mut out).expect("a parsed config packet emits");
        if lc {
            mark_link_checked(&mut out[..n]);
        }
        assert_eq!(&out[..n], &data[..len]);
        let again = ConfigRepr::parse(&Packet::new_checked(&out[..n]).unwrap()).unwrap();
        assert_eq!(again, r);
    }
    if let Ok((h, pts)) = OutputHeaderRepr::parse(&p) {
        let pts: Vec<OutputPointRepr> = pts.collect();
        let mut enc = StreamEncoder::with_seq(seq).link_checked(lc);
        let n = enc
            .encode_output(&h, &pts, &mut out)
            .expect("a parsed output packet emits");
        assert_eq!(&out[..n], &data[..len]);
        let q = Packet::new_checked(&out[..n]).unwrap();
        let (h2, pts2) = OutputHeaderRepr::parse(&q).unwrap();
        assert_eq!(h2, h);
        assert!(pts2.eq(pts.iter().copied()));
    }
});
