//! Writes what a random street is made of, for the false-length budget
//! (`scripts/false_length_budget.py`): the whole toe lines the simulator builds (before the
//! reference keeps only the observed stretches), the curb cuts, side streets and parked
//! vehicles, in CRS coordinates.
//!
//! `cargo run --release -p curbtrace-host-sim --example street_places -- SEED OUT.json`
//!
//! The street is `curbtrace simulate --scene random --seed SEED`'s; nothing is scanned. Prints
//! the street's one-line description (as `simulate` does).
//! JSON: `toes` (per toe line: `pts`, curb height `h` and category `cat` per vertex),
//! `cuts` (side, centre `u`, length, lip, transition, flush; toe points `a`/`b` at the ends
//! of the transitions and `a0`/`b0` at the ends of the lowered part), `ints` (side, `u`,
//! width, radius; `a`/`b` the mouth's ends on the main curb line, `c` its centre there),
//! `parked` (side, `u`, length; `a`/`b` the ends of the vehicle's centre line).

use curbtrace_host_sim::model::Side;
use curbtrace_host_sim::simulate::{scenes, World};
use serde_json::json;

fn side_name(s: Side) -> &'static str {
    match s {
        Side::Left => "left",
        Side::Right => "right",
    }
}

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().collect();
    let [_, seed, out] = args.as_slice() else {
        return Err("usage: street_places SEED OUT.json".into());
    };
    let seed: u64 = seed.parse().map_err(|e| format!("seed {seed:?}: {e}"))?;
    let spec = scenes::random::random(seed);
    println!("{}", spec.description);
    let world = World::build(spec.clone(), seed);
    let o = spec.origin;
    // A point `inset` metres from the curb toe towards the road centre, at `u` on `side`.
    let at = |side: Side, u: f64, inset: f64| {
        let sign = if side == Side::Left { 1.0 } else { -1.0 };
        let p = world
            .center
            .map(u, sign * (spec.half_width_at(side, u) - inset));
        [p[0] + o[0], p[1] + o[1]]
    };
    let toes: Vec<_> = world
        .ground
        .toes
        .iter()
        .map(|t| {
            json!({
                "pts": t.pts.iter().map(|p| [p[0] + o[0], p[1] + o[1]]).collect::<Vec<_>>(),
                "h": t.h_curb,
                "cat": t.category.iter().map(|c| format!("{c:?}")).collect::<Vec<_>>(),
            })
        })
        .collect();
    let cuts: Vec<_> = spec
        .curb_cuts
        .iter()
        .map(|k| {
            let (lo, hi) = (k.u - k.len / 2.0, k.u + k.len / 2.0);
            json!({
                "side": side_name(k.side), "u": k.u, "len": k.len, "lip": k.h,
                "tr": k.transition_m, "flush": k.flush,
                "a": at(k.side, lo - k.transition_m, 0.0), "b": at(k.side, hi + k.transition_m, 0.0),
                "a0": at(k.side, lo, 0.0), "b0": at(k.side, hi, 0.0),
            })
        })
        .collect();
    let ints: Vec<_> = spec
        .intersections
        .iter()
        .map(|x| {
            let (lo, hi) = spec.mouth(x);
            json!({
                "side": side_name(x.side), "u": x.u, "width": x.width, "radius": x.radius,
                "a": at(x.side, lo, 0.0), "b": at(x.side, hi, 0.0), "c": at(x.side, x.u, 0.0),
            })
        })
        .collect();
    let vehicle = |side: Side, u: f64, len: f64, inset: f64| {
        json!({
            "side": side_name(side), "u": u, "len": len,
            "a": at(side, u - len / 2.0, inset), "b": at(side, u + len / 2.0, inset),
        })
    };
    let mut parked: Vec<_> = spec
        .parked
        .iter()
        .map(|p| {
            let (len, width) = p.kind.size();
            vehicle(p.side, p.u, len, p.gap_m + width / 2.0)
        })
        .collect();
    // `parked_cars`: 4.4 × 1.7 m cars 0.3 m from the curb (docs/simulator.md).
    parked.extend(
        spec.parked_cars
            .iter()
            .map(|&(side, u)| vehicle(side, u, 4.4, 0.3 + 0.85)),
    );
    let doc = json!({"seed": seed, "toes": toes, "cuts": cuts, "ints": ints, "parked": parked});
    std::fs::write(out, doc.to_string()).map_err(|e| format!("{out}: {e}"))
}
