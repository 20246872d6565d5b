//! Development harness (tests only, ignored): runs the bend method on a simulated scene
//! with a plain f64 stand-in for the core's kernel written from SPEC §2, for tuning before
//! the core is available. `BEND_DIR=/tmp/x cargo test --release -p curbtrace-host-sim
//! bend::devrun -- --ignored --nocapture` writes `$BEND_DIR/edges.geojson`; `BEND_CONFIG`
//! names an optional TOML file of [`BendParams`]. The product never uses this code.

use super::*;
use crate::io::las_in::{read_points, ReadOptions};
use crate::replay::line_start::{LineRule, LineStartParams};
use crate::replay::project::PoseCursor;

const D_B: f64 = 0.1;
const TAU_IRREGULAR: f64 = 135.0;
const TAU_MIN: f64 = 45.0;
const TAU_MAX: f64 = 135.0;

fn windows(p: &[[f64; 2]]) -> Vec<(usize, usize)> {
    let n = p.len();
    let d = |a: usize, b: usize| (p[a][0] - p[b][0]).hypot(p[a][1] - p[b][1]);
    (0..n)
        .map(|i| {
            let mut s = i;
            while s > 0 && d(s - 1, i) <= D_B {
                s -= 1;
            }
            let mut t = i;
            while t + 1 < n && d(t + 1, i) <= D_B {
                t += 1;
            }
            (s, t)
        })
        .collect()
}

fn bend(p: &[[f64; 2]], w: &[(usize, usize)]) -> Vec<Option<f64>> {
    (0..p.len())
        .map(|i| {
            let (s, t) = w[i];
            if s == i || t == i {
                return None;
            }
            let a = [p[i][0] - p[s][0], p[i][1] - p[s][1]];
            let b = [p[t][0] - p[i][0], p[t][1] - p[i][1]];
            let ang = (a[0] * b[1] - a[1] * b[0])
                .atan2(a[0] * b[0] + a[1] * b[1])
                .abs();
            // Sign: + when i and the scanner (origin) are on opposite sides of chord s–t.
            let c = [p[t][0] - p[s][0], p[t][1] - p[s][1]];
            let side_i = c[0] * (p[i][1] - p[s][1]) - c[1] * (p[i][0] - p[s][0]);
            let side_o = c[0] * (0.0 - p[s][1]) - c[1] * (0.0 - p[s][0]);
            let sign = if side_i * side_o < 0.0 { 1.0 } else { -1.0 };
            Some(sign * ang.to_degrees())
        })
        .collect()
}

/// One line: (ρ, status) per point and the left/right candidates (line-local indices).
fn kernel_line(raw: &[[f64; 2]]) -> (Vec<f32>, Vec<u8>, Option<usize>, Option<usize>) {
    let n = raw.len();
    let w = windows(raw);
    let r0 = bend(raw, &w);
    let mut status = vec![0u8; n];
    let mut kept = Vec::new();
    for i in 0..n {
        if r0[i].is_some_and(|r| r.abs() > TAU_IRREGULAR) {
            status[i] = 1;
        } else {
            kept.push(i);
        }
    }
    let mut p: Vec<[f64; 2]> = kept.iter().map(|&i| raw[i]).collect();
    for step in 0..20 {
        let lam = if step % 2 == 0 { 0.6307 } else { -0.6732 };
        let q = p.clone();
        for k in 1..p.len().saturating_sub(1) {
            for c in 0..2 {
                p[k][c] =
                    q[k][c] + lam * (0.5 * (q[k - 1][c] - q[k][c]) + 0.5 * (q[k + 1][c] - q[k][c]));
            }
        }
    }
    let w = windows(&p);
    let r = bend(&p, &w);
    let mut rho = vec![0f32; n];
    for (k, &i) in kept.iter().enumerate() {
        match r[k] {
            Some(v) => rho[i] = v as f32,
            None => status[i] = 2,
        }
    }
    let peak = |k: usize| -> bool {
        let Some(v) = r[k] else { return false };
        if !(v > TAU_MIN && v < TAU_MAX) {
            return false;
        }
        (w[k].0..=w[k].1).all(|j| r[j].is_none_or(|u| u <= v))
    };
    let nadir = (0..p.len())
        .filter(|&k| p[k][1] < 0.0)
        .min_by(|&a, &b| p[a][0].abs().total_cmp(&p[b][0].abs()));
    let (mut left, mut right) = (None, None);
    if let Some(nd) = nadir {
        for k in (nd..p.len()).chain((0..nd).rev()) {
            let side_left = p[k][0] > 0.0;
            if (side_left && left.is_some()) || (!side_left && right.is_some()) {
                continue;
            }
            if peak(k) {
                if side_left {
                    left = Some(kept[k]);
                } else {
                    right = Some(kept[k]);
                }
            }
        }
    }
    // The walk above goes outward on each side only if each side lies on one side of the
    // nadir in scan order; it does for a profiler with the split at the top.
    (rho, status, left, right)
}

#[test]
#[ignore]
fn devrun() {
    let Ok(dir) = std::env::var("BEND_DIR") else {
        return;
    };
    let dir = std::path::PathBuf::from(dir);
    let (cols, _) = read_points(
        &dir.join("points.laz"),
        &ReadOptions::default(),
        &mut |_, _| {},
    )
    .unwrap();
    let traj = Trajectory::read_csv(&dir.join("trajectory.csv")).unwrap();
    let params: BendParams = std::env::var("BEND_CONFIG")
        .ok()
        .map(|p| toml::from_str(&std::fs::read_to_string(p).unwrap()).unwrap())
        .unwrap_or_default();
    let t0 = std::time::Instant::now();
    let n = cols.len();
    let real = std::env::var("BEND_KERNEL").is_ok_and(|v| v == "real");
    let cache = dir.join(if real {
        "real_kernel.bin"
    } else {
        "standin_kernel.bin"
    });
    let (rho, status, scanline, candidates, line) = match std::fs::read(&cache) {
        Ok(b) if b.len() >= 8 * n => read_cache(&b, n),
        _ => {
            let r = if real {
                let rep = crate::pipeline::replay_file(
                    &dir.join("points.laz"),
                    &dir.join("trajectory.csv"),
                    &crate::config::Config::default(),
                    &crate::pipeline::ExtractOptions::default(),
                    &crate::pipeline::Progress::hidden(),
                )
                .unwrap();
                assert_eq!(
                    rep.columns.len(),
                    n,
                    "points outside the trajectory: not handled here"
                );
                let k = rep.kernel;
                let lines = k.counters.scanlines as u32;
                (k.rho_deg, k.status, k.scanline, k.candidates, lines)
            } else {
                standin_kernel(&cols, &traj)
            };
            std::fs::write(&cache, write_cache(&r)).unwrap();
            r
        }
    };
    let _kernel_s = t0.elapsed().as_secs_f64();
    let input = BendInput {
        x: &cols.x,
        y: &cols.y,
        z: &cols.z,
        t: &cols.t,
        rho_deg: &rho,
        status: &status,
        scanline: &scanline,
        candidates: &candidates,
        trajectory: &traj,
    };
    if std::env::var("BEND_STAGES").is_ok() {
        let p = &params;
        let s0 = std::time::Instant::now();
        let route = route::Route::new(&traj);
        let grid = grid::PointGrid::build(input.x, input.y, 0.1, |i| input.status[i] != 255);
        let a = s0.elapsed().as_secs_f64();
        let seeds = seed::seed_points(&input, &route, p);
        let b = s0.elapsed().as_secs_f64();
        let tracks = track::track_edges(&input, &grid, &seeds, p);
        let c = s0.elapsed().as_secs_f64();
        let mut lens: Vec<(usize, f64)> = tracks
            .iter()
            .map(|t| (t.points.len(), postfilter::track_length_m(&input, t)))
            .collect();
        lens.sort_by_key(|l| std::cmp::Reverse(l.0));
        eprintln!(
            "{} tracks, longest (points, m): {:?}",
            lens.len(),
            &lens[..lens.len().min(30)]
        );
        let (ox, oy) = (traj.samples[0].x, traj.samples[0].y);
        for t in &tracks {
            let a = t.xyz[0];
            let z = *t.xyz.last().unwrap();
            eprintln!(
                "  track {:?} {} pts {:.1} m ({:.1},{:.1})->({:.1},{:.1}) covered {:.2}",
                t.side,
                t.points.len(),
                postfilter::track_length_m(&input, t),
                a[0] - ox,
                a[1] - oy,
                z[0] - ox,
                z[1] - oy,
                postfilter::covered_share(&input, &grid, t, p)
            );
        }
        let tracks = postfilter::remove_short(&input, tracks, p);
        let tracks = postfilter::remove_under_objects(&input, &grid, tracks, p);
        let d = s0.elapsed().as_secs_f64();
        let tracks = postfilter::remove_outside_roadway(&input, &route, tracks);
        let e = s0.elapsed().as_secs_f64();
        let _ = postfilter::to_edge_lines(&input, &grid, &route, &tracks, p);
        let f = s0.elapsed().as_secs_f64();
        eprintln!(
            "index {a:.3} seeds {:.3} ({} seeds) track {:.3} short+vehicle {:.3} roadway {:.3} lines {:.3}",
            b - a,
            seeds.len(),
            c - b,
            d - c,
            e - d,
            f - e
        );
    }
    let t1 = t0.elapsed().as_secs_f64();
    let edges = extract_edges(&input, &params);
    let t2 = t0.elapsed().as_secs_f64();
    eprintln!(
        "{n} points, {line} lines, {} candidates, {} edges; stand-in kernel {t1:.2} s, bend {:.2} s",
        candidates.len(),
        edges.len(),
        t2 - t1
    );
    crate::model::write_geojson(&dir.join("edges.geojson"), &edges, None).unwrap();
}

type KernelOut = (Vec<f32>, Vec<u8>, Vec<u32>, Vec<Candidate>, u32);

fn write_cache(r: &KernelOut) -> Vec<u8> {
    let mut b = Vec::new();
    for v in &r.0 {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b.extend_from_slice(&r.1);
    for v in &r.2 {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b.extend_from_slice(&r.4.to_le_bytes());
    for c in &r.3 {
        b.extend_from_slice(&c.point.to_le_bytes());
        b.extend_from_slice(&c.scanline.to_le_bytes());
        b.push(matches!(c.side, Side::Right) as u8);
    }
    b
}

fn read_cache(b: &[u8], n: usize) -> KernelOut {
    let u32_at = |o: usize| u32::from_le_bytes(b[o..o + 4].try_into().unwrap());
    let rho = (0..n).map(|i| f32::from_bits(u32_at(4 * i))).collect();
    let status = b[4 * n..5 * n].to_vec();
    let scanline = (0..n).map(|i| u32_at(5 * n + 4 * i)).collect();
    let line = u32_at(9 * n);
    let mut c = Vec::new();
    let mut o = 9 * n + 4;
    while o + 9 <= b.len() {
        c.push(Candidate {
            point: u32_at(o),
            scanline: u32_at(o + 4),
            side: if b[o + 8] == 1 {
                Side::Right
            } else {
                Side::Left
            },
        });
        o += 9;
    }
    (rho, status, scanline, c, line)
}

fn standin_kernel(cols: &crate::io::las_in::PointColumns, traj: &Trajectory) -> KernelOut {
    let n = cols.len();
    let rule = LineRule::choose(&cols.scan_angle_deg, &cols.t, &LineStartParams::default());
    let mut cur = PoseCursor::new(traj);
    let mut xz = vec![[f64::NAN; 2]; n];
    let mut ok = vec![false; n];
    for i in 0..n {
        if let Some((q, l)) = cur.frame_at(cols.t[i]) {
            xz[i] = [
                (cols.x[i] - q[0]) * l[0] + (cols.y[i] - q[1]) * l[1],
                cols.z[i] - q[2],
            ];
            ok[i] = true;
        }
    }
    let mut rho = vec![0f32; n];
    let mut status = vec![STATUS_NOT_PROCESSED; n];
    let mut scanline = vec![u32::MAX; n];
    let mut candidates = Vec::new();
    let mut start = 0;
    let mut line = 0u32;
    while start < n {
        let mut end = start + 1;
        while end < n && !rule.is_start(end, &cols.scan_angle_deg, &cols.t) {
            end += 1;
        }
        let idx: Vec<usize> = (start..end).filter(|&i| ok[i]).collect();
        if idx.len() >= 3 {
            let raw: Vec<[f64; 2]> = idx.iter().map(|&i| xz[i]).collect();
            let (r, s, l, rr) = kernel_line(&raw);
            for (k, &i) in idx.iter().enumerate() {
                rho[i] = r[k];
                status[i] = s[k];
                scanline[i] = line;
            }
            for (c, side) in [(l, Side::Left), (rr, Side::Right)] {
                if let Some(k) = c {
                    candidates.push(Candidate {
                        point: idx[k] as u32,
                        side,
                        scanline: line,
                    });
                }
            }
            line += 1;
        }
        start = end;
    }
    (rho, status, scanline, candidates, line)
}
