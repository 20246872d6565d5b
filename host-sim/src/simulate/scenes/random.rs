//! Random streets: `curbtrace simulate --scene random --seed N` draws every parameter of a
//! street from the seed — geometry, curbs, curb cuts, side streets, rows of parked
//! vehicles, the scanner's mount and rate, the speed. The distributions are listed in
//! `docs/simulator.md`; the same seed always gives the same street.

use super::common;
use crate::model::Side;
use crate::simulate::centerline::Piece;
use crate::simulate::ground::{Base, CurbShape};
use crate::simulate::scene::{
    BusBay, CurbCut, Intersection, Parked, ParkedKind, ScannerConfig, SceneSpec, VehicleBody,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Longest drive, metres.
pub const MAX_LENGTH_M: f64 = 200.0;
/// Shortest drive, metres (the pulse cap shortens a street down to this).
pub const MIN_LENGTH_M: f64 = 40.0;
/// Most pulses over the drive; returns are fewer, so a street stays below this many points.
pub const MAX_PULSES: f64 = 4.0e6;

/// A stretch along the road, metres of `u`, that a feature occupies on one side.
#[derive(Clone, Copy)]
struct Taken {
    side: Option<Side>,
    from: f64,
    to: f64,
}

fn free(taken: &[Taken], side: Side, from: f64, to: f64) -> bool {
    taken
        .iter()
        .all(|t| t.side.is_some_and(|s| s != side) || to <= t.from || from >= t.to)
}

fn either<R: Rng>(r: &mut R) -> Side {
    if r.gen_bool(0.5) {
        Side::Left
    } else {
        Side::Right
    }
}

fn log_uniform<R: Rng>(r: &mut R, lo: f64, hi: f64) -> f64 {
    (r.gen_range(lo.ln()..hi.ln())).exp()
}

/// The random street of `seed`.
pub fn random(seed: u64) -> SceneSpec {
    let r = &mut ChaCha8Rng::seed_from_u64(seed ^ 0x52A4_D0E5_7EE7_0015);

    // The vehicle and the scanner.
    let speed_kmh: f64 = r.gen_range(10.0..60.0);
    let line_rate_hz: f64 = r.gen_range(50.0..250.0);
    let mut pulses: usize = r.gen_range(1000..=5000);
    let yaw_deg = r.gen_range(0.0..60.0) * if r.gen_bool(0.5) { 1.0 } else { -1.0 };
    let pitch_deg = r.gen_range(0.0..45.0);
    let van = r.gen_bool(0.4);
    let body = VehicleBody {
        ahead_m: (
            r.gen_range(0.2..0.5),
            if van {
                r.gen_range(5.0..5.6)
            } else {
                r.gen_range(4.2..4.8)
            },
        ),
        half_width_m: if van { 1.0 } else { 0.92 },
        roof_below_m: r.gen_range(0.3..0.7),
    };
    let scanner = ScannerConfig {
        line_rate_hz,
        pulses_per_line: pulses,
        height_m: if van {
            r.gen_range(2.4..2.9)
        } else {
            r.gen_range(1.9..2.4)
        },
        yaw_deg,
        pitch_deg,
        counter_clockwise: r.gen_bool(0.5),
        range_sigma_m: r.gen_range(0.002..0.010),
        outlier_rate: 10f64.powf(r.gen_range(-4.5..-3.0)),
        min_range_m: 1.5,
        max_range_m: 120.0,
        body,
    };

    // Length within the pulse cap (10 % slack for the speed's variation).
    let v = speed_kmh / 3.6;
    let budget = 0.9 * MAX_PULSES;
    let mut length: f64 = r.gen_range(80.0..MAX_LENGTH_M);
    let fired = |len: f64, p: usize| line_rate_hz * p as f64 * len / v;
    if fired(length, pulses) > budget {
        length = (budget * v / (line_rate_hz * pulses as f64)).max(MIN_LENGTH_M);
    }
    if fired(length, pulses) > budget {
        pulses = ((budget * v / (line_rate_hz * length)) as usize).max(1000);
    }
    if fired(length, pulses) > budget {
        length = budget * v / (line_rate_hz * pulses as f64);
    }
    let scanner = ScannerConfig {
        pulses_per_line: pulses,
        ..scanner
    };

    // Centre line: straights and arcs; intersections only where the road is straight or
    // gently curved, so that a side street does not fold over the bend's centre.
    let u_start = -40.0;
    let u_end = length + 40.0;
    let mut pieces = Vec::new();
    let mut gentle: Vec<(f64, f64)> = Vec::new();
    let mut u = u_start;
    while u < u_end {
        if r.gen_bool(0.5) {
            let l = r.gen_range(20.0..100.0);
            pieces.push(Piece::Straight(l));
            gentle.push((u, u + l));
            u += l;
        } else {
            let radius = log_uniform(r, 30.0, 1000.0);
            let arc = r
                .gen_range(15.0..80.0f64)
                .min(radius * std::f64::consts::FRAC_PI_2);
            let sign = if r.gen_bool(0.5) { 1.0 } else { -1.0 };
            pieces.push(Piece::Arc(
                radius,
                sign * arc / radius * 180.0 / std::f64::consts::PI,
            ));
            if radius >= 150.0 {
                gentle.push((u, u + arc));
            }
            u += arc;
        }
    }
    // Consecutive gentle pieces form one gentle stretch.
    let mut stretches: Vec<(f64, f64)> = Vec::new();
    for g in gentle {
        match stretches.last_mut() {
            Some(last) if (last.1 - g.0).abs() < 1e-9 => last.1 = g.1,
            _ => stretches.push(g),
        }
    }
    let is_gentle = |a: f64, b: f64| stretches.iter().any(|g| g.0 <= a && b <= g.1);

    // Cross section.
    let width: f64 = r.gen_range(6.0..14.0);
    let skew = r.gen_range(-0.3..0.3);
    let (hl, hr) = (width / 2.0 + skew, width / 2.0 - skew);
    let mut half_width = vec![(0.0, hl, hr)];
    let mut taken: Vec<Taken> = Vec::new();
    let mut notes: Vec<String> = Vec::new();
    if r.gen_bool(0.25) {
        let uc = r.gen_range(20.0..(length - 20.0).max(21.0));
        let taper = r.gen_range(15.0..30.0);
        let dw = r.gen_range(1.0..3.0) * if r.gen_bool(0.5) { 1.0 } else { -1.0 };
        let w2 = (width + dw).clamp(6.0, 14.0);
        half_width.push((uc, hl, hr));
        half_width.push((uc + taper, w2 / 2.0 + skew, w2 / 2.0 - skew));
        taken.push(Taken {
            side: None,
            from: uc - 15.0,
            to: uc + taper + 15.0,
        });
        notes.push(format!("width {width:.1} → {w2:.1} m at u {uc:.0}"));
    }
    let narrow = width.min(half_width.last().map_or(width, |h| h.1 + h.2));

    // The vehicle's lane and lane changes (left-hand traffic: the left lane is the usual).
    let lane_pos = |right: bool, w: f64| {
        let off = (w / 4.0).clamp(1.5, 3.2);
        if right {
            w - off
        } else {
            off
        }
    };
    let right_lane = narrow >= 7.5 && r.gen_bool(0.35);
    let lane_from_left_m = lane_pos(right_lane, width);
    let mut lane_changes = Vec::new();
    if narrow >= 7.5 && r.gen_bool(0.3) {
        let uc = r.gen_range(10.0..(length - 30.0).max(11.0));
        lane_changes.push((uc, lane_pos(!right_lane, width)));
        notes.push(format!("lane change at u {uc:.0}"));
    }

    // Curbs.
    let h_left = r.gen_range(0.06..0.25);
    let h_right = if r.gen_bool(0.6) {
        h_left
    } else {
        r.gen_range(0.06..0.25)
    };
    let mut curb_h = vec![(0.0, h_left, h_right)];
    if r.gen_bool(0.25) {
        let uc = r.gen_range(10.0..(length - 10.0).max(11.0));
        let (a, b) = (r.gen_range(0.06..0.25), r.gen_range(0.06..0.25));
        curb_h.push((uc, h_left, h_right));
        curb_h.push((uc + r.gen_range(3.0..10.0), a, b));
        notes.push(format!(
            "curbs {:.0}/{:.0} → {:.0}/{:.0} mm at u {uc:.0}",
            h_left * 1e3,
            h_right * 1e3,
            a * 1e3,
            b * 1e3
        ));
    }
    let gutter = r.gen_bool(0.4);
    let shape = CurbShape {
        batter_ratio: r.gen_range(0.0..0.25),
        top_radius_m: r.gen_range(0.005..0.03),
        ramp_m: r.gen_range(0.5..1.5),
        walk_slope: r.gen_range(0.01..0.025),
        cross_slope: r.gen_range(0.01..0.03),
        chamfer: r.gen_bool(0.3),
        gutter_m: if gutter { r.gen_range(0.25..0.5) } else { 0.0 },
        gutter_slope: if gutter { r.gen_range(0.04..0.08) } else { 0.0 },
    };

    // Terrain: a grade along the start direction and a gentle undulation.
    let heading_deg: f64 = r.gen_range(0.0..360.0);
    let dir = (90.0 - heading_deg).to_radians();
    let grade = r.gen_range(0.0..0.06) * if r.gen_bool(0.5) { 1.0 } else { -1.0 };
    let base = Base {
        grade_x: grade * dir.cos(),
        grade_y: grade * dir.sin(),
        wave_m: r.gen_range(0.0..0.3),
    };

    // Side streets.
    let mut intersections = Vec::new();
    let n_x = match r.gen_range(0..20) {
        0..=5 => 0,
        6..=14 => 1,
        _ => 2,
    };
    for _ in 0..n_x {
        for _attempt in 0..20 {
            let x = Intersection {
                side: either(r),
                u: r.gen_range(5.0..(length - 5.0).max(6.0)),
                width: r.gen_range(6.0..10.0),
                radius: r.gen_range(3.0..15.0),
                length: 25.0,
                angle_deg: r.gen_range(60.0..120.0),
                flare: if r.gen_bool(0.3) {
                    r.gen_range(1.5..2.5)
                } else {
                    1.0
                },
            };
            let probe = SceneSpec {
                intersections: vec![x],
                ..common("probe")
            };
            let (a, b) = probe.mouth(&x);
            if is_gentle(a - 10.0, b + 10.0) && free(&taken, x.side, a - 5.0, b + 5.0) {
                taken.push(Taken {
                    side: Some(x.side),
                    from: a,
                    to: b,
                });
                intersections.push(x);
                break;
            }
        }
    }

    // A bus bay now and then.
    let mut bus_bays = Vec::new();
    if r.gen_bool(0.15) && length > 80.0 {
        let b = BusBay {
            side: either(r),
            u0: r.gen_range(5.0..length - 50.0),
            lens: [
                r.gen_range(10.0..15.0),
                r.gen_range(12.0..20.0),
                r.gen_range(8.0..12.0),
            ],
            depth: r.gen_range(2.5..3.0),
        };
        let end = b.u0 + b.lens.iter().sum::<f64>();
        if free(&taken, b.side, b.u0 - 5.0, end + 5.0) {
            taken.push(Taken {
                side: Some(b.side),
                from: b.u0,
                to: end,
            });
            bus_bays.push(b);
        }
    }

    // Curb cuts, anywhere along the drive (also in bends and next to side streets).
    let mut curb_cuts = Vec::new();
    for side in [Side::Left, Side::Right] {
        let per_100m = r.gen_range(0.0..5.0);
        let n = (per_100m * length / 100.0).round() as usize;
        for _ in 0..n {
            for _attempt in 0..20 {
                let lip = if r.gen_bool(0.2) {
                    0.0
                } else {
                    r.gen_range(0.0..0.04)
                };
                let c = CurbCut {
                    side,
                    u: r.gen_range(-5.0..length + 5.0),
                    len: r.gen_range(3.0..12.0),
                    h: lip,
                    transition_m: r.gen_range(0.3..1.5),
                    flush: r.gen_bool(0.4),
                };
                let half = c.len / 2.0 + c.transition_m;
                if free(&taken, side, c.u - half - 1.0, c.u + half + 1.0) {
                    taken.push(Taken {
                        side: Some(side),
                        from: c.u - half,
                        to: c.u + half,
                    });
                    curb_cuts.push(c);
                    break;
                }
            }
        }
    }

    // Parked cars and vans in rows; on a narrow road on one side only.
    let mut parked = Vec::new();
    let car_sides: Vec<Side> = if narrow < 9.0 {
        vec![either(r)]
    } else {
        vec![Side::Left, Side::Right]
    };
    for side in car_sides {
        let per_100m = if r.gen_bool(0.3) {
            0.0
        } else {
            r.gen_range(0.0..8.0)
        };
        let n = (per_100m * length / 100.0).round() as usize;
        let mut u = r.gen_range(-10.0..20.0);
        let mut placed = 0;
        while placed < n && u < length + 10.0 {
            let kind = if r.gen_bool(0.25) {
                ParkedKind::Van
            } else {
                ParkedKind::Car
            };
            let (len, _) = kind.size();
            if !free(&taken, side, u - 1.0, u + len + 1.0) {
                u += 2.0;
                continue;
            }
            parked.push(Parked {
                side,
                u: u + len / 2.0,
                gap_m: r.gen_range(0.1..0.5),
                kind,
            });
            placed += 1;
            u += len
                + if r.gen_bool(0.15) {
                    r.gen_range(20.0..60.0)
                } else {
                    r.gen_range(1.0..20.0)
                };
        }
    }

    // Weeds and leaves at the joint, poles, sidewalks.
    let mut weeds = Vec::new();
    for side in [Side::Left, Side::Right] {
        if r.gen_bool(0.5) {
            for _ in 0..r.gen_range(1..=3) {
                let a = r.gen_range(-20.0..length);
                weeds.push((side, a, a + r.gen_range(5.0..40.0)));
            }
        }
    }
    let leaves_per_100m = r.gen_range(0.0..150.0);
    let pole_spacing_m = r.gen_range(15.0..50.0);
    let sidewalk_m = (r.gen_range(1.5..4.0), r.gen_range(1.5..4.0));
    let origin = [
        (r.gen_range(300_000.0..700_000.0f64) * 4.0).round() / 4.0,
        (r.gen_range(3_500_000.0..4_800_000.0f64) * 4.0).round() / 4.0,
        r.gen_range(2.0..60.0f64).round(),
    ];

    let far = if lane_from_left_m > width / 2.0 {
        "left"
    } else {
        "right"
    };
    let description = format!(
        "seed {seed}: {length:.0} m at {speed_kmh:.0} km/h, {line_rate_hz:.0} lines/s × {pulses} pulses ({:.3} m between lines), mount yaw {yaw_deg:.0}° pitch {pitch_deg:.0}° on a {}, noise {:.1} mm; width {width:.1} m, lane {lane_from_left_m:.1} m from the left curb (far side {far}); curbs {:.0}/{:.0} mm, batter {:.2}, {}{}, crossfall {:.1} %, grade {:.1} %; {} curb cuts ({} without lip), {} side streets, {} bus bays, {} parked ({} vans){}{}",
        v / line_rate_hz,
        if van { "van" } else { "car" },
        scanner.range_sigma_m * 1e3,
        h_left * 1e3,
        h_right * 1e3,
        shape.batter_ratio,
        if shape.chamfer { "chamfered" } else { "rounded" },
        if gutter { ", gutter" } else { "" },
        shape.cross_slope * 100.0,
        grade.abs() * 100.0,
        curb_cuts.len(),
        curb_cuts.iter().filter(|c| c.h == 0.0).count(),
        intersections.len(),
        bus_bays.len(),
        parked.len(),
        parked.iter().filter(|p| p.kind == ParkedKind::Van).count(),
        if notes.is_empty() { "" } else { "; " },
        notes.join("; ")
    );

    SceneSpec {
        origin,
        heading_deg,
        pieces,
        u_range: (u_start, u_end),
        drive: (0.0, length),
        speed_kmh,
        half_width,
        curb_h,
        lane_from_left_m,
        lane_changes,
        description,
        sidewalk_m,
        curb_cuts,
        intersections,
        bus_bays,
        parked,
        weeds,
        leaves_per_100m,
        pole_spacing_m,
        shape,
        base,
        scanner,
        ..common(&format!("random-{seed}"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_stay_within_their_ranges_and_the_pulse_cap() {
        for seed in 0..200 {
            let s = random(seed);
            let len = s.drive.1 - s.drive.0;
            assert!((MIN_LENGTH_M * 0.5..=MAX_LENGTH_M).contains(&len), "{len}");
            let sc = &s.scanner;
            let fired = sc.line_rate_hz * sc.pulses_per_line as f64 * len / (s.speed_kmh / 3.6);
            assert!(fired <= 0.9 * MAX_PULSES + 1.0, "seed {seed}: {fired}");
            assert!(sc.yaw_deg.abs() <= 60.0 && (0.0..=45.0).contains(&sc.pitch_deg));
            assert!((50.0..=250.0).contains(&sc.line_rate_hz));
            assert!((1000..=5000).contains(&sc.pulses_per_line));
            for row in &s.curb_h {
                assert!((0.06..=0.25).contains(&row.1) && (0.06..=0.25).contains(&row.2));
            }
            for row in &s.half_width {
                assert!((5.5..=14.5).contains(&(row.1 + row.2)));
            }
            for c in &s.curb_cuts {
                assert!((0.0..=0.04).contains(&c.h) && (3.0..=12.0).contains(&c.len));
            }
            for x in &s.intersections {
                assert!((60.0..=120.0).contains(&x.angle_deg) && (3.0..=15.0).contains(&x.radius));
            }
            for p in &s.parked {
                assert!((0.1..=0.5).contains(&p.gap_m));
            }
        }
    }

    #[test]
    fn seeds_differ_and_repeat() {
        assert_eq!(random(7).description, random(7).description);
        assert_ne!(random(7).description, random(8).description);
    }
}
