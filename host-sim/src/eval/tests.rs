//! Tests of the evaluation: sampling, matching, every metric and the table.

use super::matching::sample_polyline;
use super::*;
use crate::model::{Category, EdgeLine, Side};

// Large CRS offsets, as real data has: the local origin must keep precision.
const X0: f64 = 500_000.0;
const Y0: f64 = 4_000_000.0;

fn line(pts: &[(f64, f64)], side: Side, cat: Option<Category>) -> EdgeLine {
    EdgeLine {
        points: pts.iter().map(|&(x, y)| [X0 + x, Y0 + y, 10.0]).collect(),
        side,
        category: cat,
        method: None,
        curb_height_m: None,
        detail: None,
    }
}

fn curb(pts: &[(f64, f64)]) -> EdgeLine {
    line(pts, Side::Left, Some(Category::Curb))
}

fn eval(r: &[EdgeLine], e: &[EdgeLine]) -> EvalReport {
    evaluate(r, e, &EvalParams::default()).unwrap()
}

fn close(a: Option<f64>, b: f64, tol: f64) -> bool {
    a.is_some_and(|a| (a - b).abs() <= tol)
}

#[test]
fn sampling_weights_add_up_to_the_length() {
    let (s, w) = sample_polyline(&[[0.0, 0.0], [3.0, 4.0], [3.0, 4.003]], 0.01);
    assert_eq!(s.len(), 501); // 5.003 m in pieces of at most 10 mm
    assert!((w * s.len() as f64 - 5.003).abs() < 1e-12);
    // First sample at half a piece along the first segment (direction 0.6, 0.8).
    assert!((s[0][0] - 0.6 * w / 2.0).abs() < 1e-12);
    let (s, _) = sample_polyline(&[[0.0, 0.0], [1.0, 0.0]], 0.01);
    assert_eq!(s.len(), 100); // exactly 100 steps stays 100
    assert!(sample_polyline(&[[1.0, 1.0], [1.0, 1.0]], 0.01)
        .0
        .is_empty());
}

#[test]
fn identical_lines_score_100_percent_and_rms_zero() {
    let r = curb(&[(0.0, 0.0), (10.0, 0.0), (20.0, 5.0)]);
    let rep = eval(std::slice::from_ref(&r), std::slice::from_ref(&r));
    let t = &rep.total;
    assert!(close(t.completeness_pct, 100.0, 1e-9));
    assert!(close(t.correctness_pct, 100.0, 1e-9));
    assert!(close(t.quality_pct, 100.0, 1e-9));
    assert!(close(t.rms_mm, 0.0, 1e-6));
    assert_eq!((t.gaps, t.outside_pieces), (0, 0));
    let len = 10.0 + 125f64.sqrt();
    assert!((t.reference_m - len).abs() < 1e-9 && (t.extracted_m - len).abs() < 1e-9);
}

#[test]
fn offset_30_mm_is_inside_the_buffer_with_rms_30_mm() {
    let r = curb(&[(0.0, 0.0), (10.0, 0.0)]);
    let e = curb(&[(0.0, 0.03), (10.0, 0.03)]);
    let t = eval(&[r], &[e]).total;
    assert!(close(t.completeness_pct, 100.0, 1e-9));
    assert!(close(t.correctness_pct, 100.0, 1e-9));
    assert!(close(t.quality_pct, 100.0, 1e-9));
    assert!(close(t.rms_mm, 30.0, 1e-6), "{:?}", t.rms_mm);
}

#[test]
fn offset_80_mm_is_outside_the_buffer() {
    let r = curb(&[(0.0, 0.0), (10.0, 0.0)]);
    let e = curb(&[(0.0, -0.08), (10.0, -0.08)]);
    let t = eval(&[r], &[e]).total;
    assert!(close(t.completeness_pct, 0.0, 1e-9));
    assert!(close(t.correctness_pct, 0.0, 1e-9));
    assert!(close(t.quality_pct, 0.0, 1e-9));
    assert_eq!(t.rms_mm, None);
    // The whole reference is one gap, the whole extraction one outside piece.
    assert_eq!((t.gaps, t.outside_pieces), (1, 1));
    assert!((t.gap_length_m - 10.0).abs() < 1e-9);
    assert!((t.outside_length_m - 10.0).abs() < 1e-9);
}

#[test]
fn half_the_length_gives_half_completeness_and_full_correctness() {
    let r = curb(&[(0.0, 0.0), (10.0, 0.0)]);
    let e = curb(&[(0.0, 0.0), (5.0, 0.0)]);
    let t = eval(&[r], &[e]).total;
    // The buffer reaches 50 mm past the extracted end: 5.05 m of 10 m are matched.
    assert!(
        close(t.completeness_pct, 50.5, 1e-6),
        "{:?}",
        t.completeness_pct
    );
    assert!(close(t.correctness_pct, 100.0, 1e-9));
    // Quality = TP / (extracted + FN) = 5 / (5 + 4.95).
    assert!(
        close(t.quality_pct, 500.0 / 9.95, 1e-6),
        "{:?}",
        t.quality_pct
    );
    assert_eq!(t.gaps, 1);
    assert!((t.gap_length_m - 4.95).abs() < 1e-6);
}

#[test]
fn a_spurious_line_lowers_correctness_by_its_share() {
    let r = curb(&[(0.0, 0.0), (10.0, 0.0)]);
    let good = curb(&[(0.0, 0.0), (10.0, 0.0)]);
    // 2.5 m long, 1 m off the reference: attributed to the left curb, FP.
    let bad = curb(&[(2.0, 1.0), (4.5, 1.0)]);
    let rep = eval(&[r], &[good, bad]);
    for m in [
        &rep.total,
        &rep.sides[0].total,
        &rep.sides[0].categories[0].metrics,
    ] {
        assert!(
            close(m.correctness_pct, 80.0, 1e-6),
            "{:?}",
            m.correctness_pct
        );
        assert!(close(m.completeness_pct, 100.0, 1e-9));
        assert!(close(m.quality_pct, 80.0, 1e-6));
        assert_eq!(m.outside_pieces, 1);
        assert!((m.outside_length_m - 2.5).abs() < 1e-9);
    }
    assert_eq!(rep.extracted_unattributed_m, 0.0);
}

#[test]
fn lines_farther_than_2_m_count_as_fp_in_the_total_only() {
    let r = curb(&[(0.0, 0.0), (10.0, 0.0)]);
    let good = curb(&[(0.0, 0.0), (10.0, 0.0)]);
    let far = curb(&[(0.0, 2.5), (10.0, 2.5)]);
    let rep = eval(&[r], &[good, far]);
    assert!(close(rep.total.correctness_pct, 50.0, 1e-6));
    assert!((rep.extracted_unattributed_m - 10.0).abs() < 1e-9);
    assert_eq!(rep.total.outside_pieces, 1);
    assert_eq!(rep.sides.len(), 1);
    let left = &rep.sides[0].total;
    assert!(close(left.correctness_pct, 100.0, 1e-9));
    assert_eq!(left.outside_pieces, 0);
    assert!((left.extracted_m - 10.0).abs() < 1e-9);
}

#[test]
fn samples_take_side_and_category_of_the_nearest_reference() {
    // Left: a curb (0–10 m) then a curb cut (10–14 m) along y = 0.
    // Right: a curb along y = -8 from 0 to 10 m, and a bus bay from 10 to 20 m.
    let refs = vec![
        line(&[(0.0, 0.0), (10.0, 0.0)], Side::Left, Some(Category::Curb)),
        line(
            &[(10.0, 0.0), (14.0, 0.0)],
            Side::Left,
            Some(Category::CurbCut),
        ),
        line(
            &[(0.0, -8.0), (10.0, -8.0)],
            Side::Right,
            Some(Category::Curb),
        ),
        line(
            &[(10.0, -8.0), (20.0, -9.0)],
            Side::Right,
            Some(Category::BusBay),
        ),
    ];
    // One extracted line along the whole left edge, labelled "right" on purpose: its
    // own side must be ignored. Right side: only the curb, 20 mm off.
    let exts = vec![
        line(&[(0.0, 0.0), (14.0, 0.0)], Side::Right, None),
        line(&[(0.0, -7.98), (10.0, -7.98)], Side::Left, None),
    ];
    let rep = eval(&refs, &exts);
    assert_eq!(rep.sides.len(), 2);
    let left = &rep.sides[0];
    assert_eq!(left.side, Side::Left);
    let cats: Vec<_> = left.categories.iter().map(|c| c.category).collect();
    assert_eq!(cats, [Some(Category::Curb), Some(Category::CurbCut)]);
    assert!((left.categories[0].metrics.extracted_m - 10.0).abs() < 1e-6);
    assert!((left.categories[1].metrics.extracted_m - 4.0).abs() < 1e-6);
    assert!(close(left.total.completeness_pct, 100.0, 1e-9));
    let right = &rep.sides[1];
    let cats: Vec<_> = right.categories.iter().map(|c| c.category).collect();
    assert_eq!(cats, [Some(Category::Curb), Some(Category::BusBay)]);
    let curb_r = &right.categories[0].metrics;
    assert!(close(curb_r.completeness_pct, 100.0, 1e-9));
    assert!(close(curb_r.rms_mm, 20.0, 1e-6));
    let bay = &right.categories[1].metrics;
    // The buffer of the curb's extracted end reaches 50 mm into the bus bay (almost
    // along it): ~0.05 m of its 10.05 m are matched.
    // Solving |bay(s) − (10, −7.98)| = 0.05 gives s = 0.044 m of 10.05 m: 0.44 %, to
    // within one 10 mm sample (0.1 %).
    assert!(
        close(bay.completeness_pct, 0.438, 0.1),
        "{:?}",
        bay.completeness_pct
    );
    assert_eq!(bay.extracted_m, 0.0);
    assert_eq!(bay.correctness_pct, None);
    assert_eq!(bay.gaps, 1);
    // Total RMS: 14 m at 0 mm and 10 m at 20 mm.
    assert!(close(
        rep.total.rms_mm,
        (10.0 * 400.0 / 24.0f64).sqrt(),
        1e-6
    ));
    // The sides' columns add up to the total.
    let sum: f64 = rep.sides.iter().map(|s| s.total.reference_m).sum();
    assert!((sum - rep.total.reference_m).abs() < 1e-9);
}

#[test]
fn gaps_shorter_than_a_decimetre_do_not_count() {
    let r = curb(&[(0.0, 0.0), (10.0, 0.0)]);
    // Holes of 0.5 m and 0.15 m in the extraction: the buffer shortens each by 2 × 50 mm,
    // leaving unmatched runs of 0.40 m (a gap) and 0.05 m (not a gap).
    let e = vec![
        curb(&[(0.0, 0.0), (4.0, 0.0)]),
        curb(&[(4.5, 0.0), (7.0, 0.0)]),
        curb(&[(7.15, 0.0), (10.0, 0.0)]),
    ];
    let t = eval(&[r], &e).total;
    assert_eq!(t.gaps, 1);
    assert!((t.gap_length_m - 0.40).abs() < 1e-6, "{}", t.gap_length_m);
    assert!((t.fn_m - 0.45).abs() < 1e-6, "{}", t.fn_m);
}

#[test]
fn an_extracted_line_leaving_the_buffer_is_one_outside_piece() {
    let r = curb(&[(0.0, 0.0), (10.0, 0.0)]);
    // Leaves the buffer between x = 4 and x = 6 at 0.2 m.
    let e = curb(&[
        (0.0, 0.0),
        (4.0, 0.0),
        (4.0, 0.2),
        (6.0, 0.2),
        (6.0, 0.0),
        (10.0, 0.0),
    ]);
    let t = eval(&[r], &[e]).total;
    assert_eq!(t.outside_pieces, 1);
    // 2 m at 0.2 m plus 2 × 0.15 m of the vertical legs beyond 50 mm.
    assert!(
        (t.outside_length_m - 2.3).abs() < 0.011,
        "{}",
        t.outside_length_m
    );
    // The reference between the legs is more than 50 mm from the extraction except
    // within 50 mm of each leg: 1.9 m unmatched, one gap.
    assert!(
        close(t.completeness_pct, 81.0, 1e-6),
        "{:?}",
        t.completeness_pct
    );
    assert_eq!(t.gaps, 1);
    assert!((t.gap_length_m - 1.9).abs() < 1e-6);
}

#[test]
fn empty_inputs_and_bad_parameters() {
    let r = curb(&[(0.0, 0.0), (10.0, 0.0)]);
    let t = eval(std::slice::from_ref(&r), &[]).total;
    assert!(close(t.completeness_pct, 0.0, 1e-9));
    assert_eq!(t.correctness_pct, None);
    let rep = eval(&[], std::slice::from_ref(&r));
    assert!(close(rep.total.correctness_pct, 0.0, 1e-9));
    assert!(rep.sides.is_empty());
    let bad = EvalParams {
        buffer_m: 0.0,
        ..Default::default()
    };
    assert!(matches!(
        evaluate(std::slice::from_ref(&r), std::slice::from_ref(&r), &bad),
        Err(EvalError::BadParam {
            name: "buffer_m",
            ..
        })
    ));
    let mut nan = r.clone();
    nan.points[1][1] = f64::NAN;
    assert_eq!(
        evaluate(&[r], &[nan], &EvalParams::default()),
        Err(EvalError::NonFinite {
            which: "extracted",
            index: 0
        })
    );
}

#[test]
fn markdown_table_has_the_papers_rows_and_columns() {
    let refs = vec![
        line(&[(0.0, 0.0), (10.0, 0.0)], Side::Left, Some(Category::Curb)),
        line(
            &[(0.0, -8.0), (10.0, -8.0)],
            Side::Right,
            Some(Category::Intersection),
        ),
    ];
    let rep = eval(&refs, &refs[..1]);
    let md = rep.to_markdown();
    let header = md.lines().next().unwrap();
    assert!(header.contains("Total") && header.contains("Left: Curb"));
    assert!(header.contains("Right: Intersection"), "{md}");
    assert!(!header.contains("Bus bay"));
    let comp = md
        .lines()
        .find(|l| l.starts_with("| Completeness"))
        .unwrap();
    let cells: Vec<&str> = comp.split('|').map(str::trim).collect();
    // Total 50 %, Left total 100 %, Left curb 100 %, Right total 0 %, Right inter. 0 %.
    assert_eq!(&cells[2..7], &["50.0", "100.0", "100.0", "0.0", "0.0"]);
    let corr = md.lines().find(|l| l.starts_with("| Correctness")).unwrap();
    assert!(corr.contains('–')); // no extraction on the right
    let json: serde_json::Value = serde_json::from_str(&rep.to_json()).unwrap();
    assert_eq!(json["total"]["completeness_pct"], 50.0);
    assert_eq!(json["sides"][1]["side"], "right");
    assert_eq!(
        json["sides"][1]["categories"][0]["category"],
        "intersection"
    );
}

#[test]
fn kilometres_of_lines_are_fast() {
    // 2 km of reference and extraction (200 000 samples each) in a wiggly line.
    let pts: Vec<(f64, f64)> = (0..=2000)
        .map(|i| (i as f64, (i as f64 * 0.01).sin() * 5.0))
        .collect();
    let r = curb(&pts);
    let start = std::time::Instant::now();
    let t = eval(std::slice::from_ref(&r), std::slice::from_ref(&r)).total;
    assert!(close(t.completeness_pct, 100.0, 1e-9));
    assert!(start.elapsed().as_secs_f64() < 20.0);
}
