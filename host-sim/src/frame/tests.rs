//! The frame job on a synthetic HDL-64-like sweep: a road with a 12 cm kerb 5.5 m to the
//! left and 4 m to the right, and on the left a parked car and a low wall standing on the
//! road.

use super::*;
use crate::io::sweep::SweepFormat;

const H: f32 = 1.73;
const LEFT: f32 = 5.5;
const RIGHT: f32 = -4.0;
const KERB: f32 = 0.12;
/// The parked car: x from, x to, y from (its flank facing the road), y to, height.
const CAR: [f32; 5] = [8.0, 12.5, 3.5, 5.3, 1.5];
/// A low wall (a planter) on the road: x from, x to, y from, y to, height.
const WALL: [f32; 5] = [-9.0, -5.0, 4.5, 5.0, 0.5];

/// Horizontal distance and height where a beam at azimuth `phi` and elevation `el` (both
/// radians, el < 0) first meets the scene, if it does within 60 m.
fn cast(phi: f32, el: f32, car: bool) -> Option<(f32, f32)> {
    let (c, s, t) = (phi.cos(), phi.sin(), (-el).tan());
    let z_at = |d: f32| -d * t;
    let mut best: Option<(f32, f32)> = None;
    let mut take = |d: f32, z: f32| {
        if d > 0.0 && best.is_none_or(|b| d < b.0) {
            best = Some((d, z));
        }
    };
    // Road, and the kerb tops beyond either kerb line.
    let d_road = H / t;
    let d_top = (H - KERB) / t;
    let beyond = |d: f32| {
        let y = d * s;
        !(RIGHT..=LEFT).contains(&y)
    };
    if beyond(d_top) {
        take(d_top, -(H - KERB));
    } else if !beyond(d_road) {
        take(d_road, -H);
    } else {
        // The kerb face, where the beam crosses the kerb line between road and top.
        let line = if s > 0.0 { LEFT } else { RIGHT };
        take(line / s, z_at(line / s));
    }
    if car {
        // The car's flank (y = CAR[2]) and rear (x = CAR[0]), from 0.25 m above the road.
        let bottom = -H + 0.25;
        let top = -H + CAR[4];
        if s > 0.0 {
            let d = CAR[2] / s;
            let (x, z) = (d * c, z_at(d));
            if (CAR[0]..=CAR[1]).contains(&x) && (bottom..=top).contains(&z) {
                take(d, z);
            }
        }
        if c > 0.0 {
            let d = CAR[0] / c;
            let (y, z) = (d * s, z_at(d));
            if (CAR[2]..=CAR[3]).contains(&y) && (bottom..=top).contains(&z) {
                take(d, z);
            }
        }
        // The wall's face (y = WALL[2], from the road up) and its top.
        let top = -H + WALL[4];
        if s > 0.0 {
            let d = WALL[2] / s;
            let (x, z) = (d * c, z_at(d));
            if (WALL[0]..=WALL[1]).contains(&x) && (-H..=top).contains(&z) {
                take(d, z);
            }
        }
        let d = (H - WALL[4]) / t;
        if (WALL[0]..=WALL[1]).contains(&(d * c)) && (WALL[2]..=WALL[3]).contains(&(d * s)) {
            take(d, top);
        }
    }
    best.filter(|b| b.0 < 60.0)
}

/// 48 lasers from −24° to −6°, 0.18° apart in azimuth, stored laser by laser.
fn scene(car: bool) -> Sweep {
    let mut s = Sweep::with_capacity(SweepFormat::Kitti, 100_000);
    let mut noise = 0x2545_f491u32;
    for ring in 0..48u16 {
        let el = (-24.0 + 18.0 * f32::from(ring) / 47.0).to_radians();
        for j in 0..2000 {
            let phi = (j as f32 * 0.18).to_radians();
            let Some((d, z)) = cast(phi, el, car) else {
                continue;
            };
            noise ^= noise << 13;
            noise ^= noise >> 17;
            noise ^= noise << 5;
            let n = (noise as f32 / u32::MAX as f32 - 0.5) * 0.01;
            s.push(d * phi.cos(), d * phi.sin(), z + n, 0.0, ring);
        }
    }
    s.rings = 64;
    s
}

fn run(s: &Sweep) -> FrameResult {
    let mut pipe = Box::new(FramePipeline::new());
    extract_frame(s, &SensorModel::HDL64, &FrameParams::default(), &mut pipe).unwrap()
}

#[test]
fn both_kerbs_are_found_on_their_sides_with_their_height() {
    let s = scene(false);
    let r = run(&s);
    for (side, y0) in [(Side::Left, LEFT), (Side::Right, RIGHT)] {
        let lines: Vec<&CurbLine> = r.lines.iter().filter(|l| l.side == side).collect();
        assert!(!lines.is_empty(), "{side:?}: {:?}", r.counters);
        let total: usize = lines.iter().map(|l| l.points.len()).sum();
        assert!(total >= 10, "{side:?}: {total} vertices");
        for l in &lines {
            for p in &l.points {
                assert!((p[1] as f32 - y0).abs() < 0.1, "{side:?} vertex {p:?}");
            }
            assert!(
                (l.height_m as f32 - KERB).abs() < 0.02,
                "{side:?} {}",
                l.height_m
            );
        }
    }
}

/// The sign convention: left is left for both half-arcs. Ahead of the car and behind it,
/// the kernel's left candidates lie on the left kerb and its right ones on the right kerb.
#[test]
fn left_is_left_ahead_and_behind() {
    let s = scene(false);
    let r = run(&s);
    for half in [Half::Front, Half::Rear] {
        for (side, y0) in [(Side::Left, LEFT), (Side::Right, RIGHT)] {
            let on_kerb = r
                .candidates
                .iter()
                .filter(|c| c.half == half && c.side == side)
                .filter(|c| matches!(c.verdict, Verdict::Curb { .. }))
                .filter(|c| (s.y[c.point as usize] - y0).abs() < 0.1)
                .count();
            let x_sign = r
                .candidates
                .iter()
                .filter(|c| c.half == half)
                .all(|c| (s.x[c.point as usize] >= 0.0) == (half == Half::Front));
            assert!(on_kerb >= 5, "{half:?} {side:?}: {on_kerb}");
            assert!(x_sign, "{half:?}");
        }
    }
}

/// The car's flank is a straight vertical run in x′–z′ with no neighbour across its ends,
/// so the kernel marks no bend on it; the low wall's foot is a sharp bend and gets
/// candidates, which the check rejects (it rises 0.5 m). Between the obstacles' faces and
/// the kerb nothing is accepted, and the kerb is still found.
#[test]
fn a_parked_car_and_a_low_wall_are_not_taken_for_curbs() {
    let s = scene(true);
    let r = run(&s);
    let off_kerb = |y: f32| (CAR[2] - 0.3..LEFT - 0.2).contains(&y);
    let rejected: Vec<(f32, f32, f32, Verdict)> = r
        .candidates
        .iter()
        .filter(|c| !matches!(c.verdict, Verdict::Curb { .. }))
        .map(|c| {
            let i = c.point as usize;
            (s.x[i], s.y[i], s.z[i], c.verdict)
        })
        .collect();
    let at_wall = r
        .candidates
        .iter()
        .filter(|c| {
            let i = c.point as usize;
            (WALL[0] - 0.5..=WALL[1] + 0.5).contains(&s.x[i]) && off_kerb(s.y[i])
        })
        .collect::<Vec<_>>();
    assert!(at_wall.len() >= 3, "{:?} {rejected:?}", r.counters);
    assert!(r.counters.objects >= 3, "{:?}", r.counters);
    for c in &r.candidates {
        let i = c.point as usize;
        if c.side == Side::Left && off_kerb(s.y[i]) {
            assert!(
                !matches!(c.verdict, Verdict::Curb { .. }),
                "{:?} at {} {}",
                c.verdict,
                s.x[i],
                s.y[i]
            );
        }
    }
    for l in &r.lines {
        for p in &l.points {
            assert!(
                !(l.side == Side::Left && off_kerb(p[1] as f32)),
                "vertex off the kerb: {p:?}"
            );
        }
    }
    // The kerb is still found on the left, ahead of and behind the obstacles.
    assert!(r
        .lines
        .iter()
        .any(|l| l.side == Side::Left && l.points.len() >= 3));
}
