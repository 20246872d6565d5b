//! The demo's outputs after extraction: evaluate, draw the pictures and write
//! `report.md` (metrics table, links to the pictures, the parameters, timings) and
//! `eval.json`.
//!
//! [`write_demo_outputs`] takes the pieces — points, trajectory, reference and extracted
//! lines, optionally one scanline for the cross-section, the run's parameters and timings —
//! so that `curbtrace demo` (and the end-to-end tests) only have to simulate and extract.
//! [`report_markdown`] alone turns finished pieces into the Markdown text.

use super::{evaluate, EvalError, EvalParams, EvalReport};
use crate::model::EdgeLine;
use crate::plot::{
    cross_section_png, top_view_png, windows_of_interest, Cloud, CrossSection, PlotError, TopView,
    Window,
};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Why the demo's outputs could not be written.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// A file or directory could not be written.
    #[error("{path}: {what}")]
    Io {
        /// The file or directory.
        path: String,
        /// The cause.
        what: String,
    },
    /// The evaluation failed.
    #[error("evaluating the extracted edges: {0}")]
    Eval(#[from] EvalError),
    /// A picture failed.
    #[error("{0}")]
    Plot(#[from] PlotError),
}

/// A picture in the report: file name relative to the report, and a caption.
#[derive(Clone, Debug, PartialEq)]
pub struct Picture {
    /// File name, relative to the report's directory.
    pub file: String,
    /// What it shows.
    pub caption: String,
}

/// Everything `report.md` shows.
#[derive(Clone, Debug)]
pub struct DemoReport<'a> {
    /// Scene name (`tiny`, `kawasaki`, …).
    pub scene: String,
    /// Method name (`bend`, `qiu`).
    pub method: String,
    /// The command that made it, shown so the run can be repeated.
    pub command: String,
    /// The evaluation.
    pub eval: &'a EvalReport,
    /// Pictures, in the order shown.
    pub pictures: Vec<Picture>,
    /// Facts about the scene and the run: (what, value), e.g. ("points", "1 234 567").
    pub facts: Vec<(String, String)>,
    /// The method's parameters: (name, value).
    pub parameters: Vec<(String, String)>,
    /// Wall time per stage: (stage, seconds).
    pub timings: Vec<(String, f64)>,
    /// Files written: (file name relative to the report, what it is).
    pub files: Vec<(String, String)>,
}

fn pct(v: Option<f64>) -> String {
    v.map_or("–".to_string(), |v| format!("{v:.1} %"))
}

/// Escapes the characters that would break a Markdown table cell.
fn cell(s: &str) -> String {
    s.replace('|', "\\|").replace('\n', " ")
}

/// The Markdown text of `report.md`.
pub fn report_markdown(r: &DemoReport) -> String {
    let mut md = String::new();
    let t = &r.eval.total;
    md.push_str(&format!(
        "# curbtrace demo — scene `{}`, method `{}`\n\n",
        r.scene, r.method
    ));
    md.push_str(&format!("Made by `{}`.\n\n", r.command));
    md.push_str(&format!(
        "**Result:** completeness {}, correctness {}, quality {}, RMS difference {} over \
         {:.1} m of reference and {:.1} m of extracted edges (buffer {:.0} mm).\n\n",
        pct(t.completeness_pct),
        pct(t.correctness_pct),
        pct(t.quality_pct),
        t.rms_mm.map_or("–".to_string(), |v| format!("{v:.1} mm")),
        t.reference_m,
        t.extracted_m,
        r.eval.params.buffer_m * 1000.0
    ));

    md.push_str("## Metrics\n\n");
    md.push_str(
        "Heipke et al. (1997) as used by Honma et al. (Tables 2 and 3), computed on samples \
         every 10 mm: completeness = matched reference / reference; correctness = extracted \
         within the buffer of a reference (TP) / extracted; quality = TP / (TP + FP + FN) with \
         TP and FP measured on the extraction and FN on the reference; RMS over the TP \
         samples. *Gaps (Heipke)* are runs of unmatched reference longer than 0.1 m; \
         *pieces outside the buffer* are Honma et al.'s wording of gaps (extracted runs \
         outside the buffer). An extracted sample belongs to the side and category of its \
         nearest reference line.\n\n",
    );
    md.push_str(&r.eval.to_markdown());
    md.push('\n');

    if !r.pictures.is_empty() {
        md.push_str("## Pictures\n\n");
        for p in &r.pictures {
            md.push_str(&format!(
                "### {}\n\n![{}]({})\n\n",
                p.caption,
                p.caption.replace(['[', ']'], ""),
                p.file
            ));
        }
    }

    let table = |md: &mut String, title: &str, head: (&str, &str), rows: &[(String, String)]| {
        if rows.is_empty() {
            return;
        }
        md.push_str(&format!(
            "## {title}\n\n| {} | {} |\n|:--|--:|\n",
            head.0, head.1
        ));
        for (a, b) in rows {
            md.push_str(&format!("| {} | {} |\n", cell(a), cell(b)));
        }
        md.push('\n');
    };
    table(&mut md, "Scene and run", ("what", "value"), &r.facts);
    table(&mut md, "Parameters", ("parameter", "value"), &r.parameters);
    let timings: Vec<(String, String)> = r
        .timings
        .iter()
        .map(|(s, t)| (s.clone(), format!("{t:.2}")))
        .collect();
    table(&mut md, "Timings", ("stage", "seconds"), &timings);
    if !r.files.is_empty() {
        md.push_str("## Files\n\n| file | what |\n|:--|:--|\n");
        for (f, what) in &r.files {
            md.push_str(&format!("| [`{f}`]({f}) | {} |\n", cell(what)));
        }
        md.push('\n');
    }
    md
}

/// Writes `report.md` into `path`.
pub fn write_report(path: &Path, r: &DemoReport) -> Result<(), ReportError> {
    std::fs::write(path, report_markdown(r)).map_err(|e| ReportError::Io {
        path: path.display().to_string(),
        what: e.to_string(),
    })
}

/// The pieces [`write_demo_outputs`] needs.
#[derive(Clone, Debug)]
pub struct DemoInputs<'a> {
    /// Scene name.
    pub scene: String,
    /// Method name.
    pub method: String,
    /// The command line, for the report.
    pub command: String,
    /// The points (world coordinates).
    pub cloud: Cloud<'a>,
    /// Trajectory (scanner origin) in world x, y.
    pub trajectory_xy: &'a [[f64; 2]],
    /// Reference lines.
    pub reference: &'a [EdgeLine],
    /// Extracted edges.
    pub extracted: &'a [EdgeLine],
    /// One scanline to draw as a cross-section, if the caller has one.
    pub cross_section: Option<CrossSection<'a>>,
    /// Zoom windows beyond those found from the reference (e.g. a parked car the simulator
    /// knows of): (file stem, caption, window).
    pub extra_windows: Vec<(String, String, Window)>,
    /// Facts for the report (points, scanlines, length driven …).
    pub facts: Vec<(String, String)>,
    /// The method's parameters.
    pub parameters: Vec<(String, String)>,
    /// Timings so far (simulation, extraction …); evaluation and pictures are added.
    pub timings: Vec<(String, f64)>,
    /// Files already written into the output directory (e.g. `points.laz`,
    /// `edges.geojson`): (file name, what).
    pub files: Vec<(String, String)>,
}

/// What [`write_demo_outputs`] produced.
#[derive(Clone, Debug)]
pub struct DemoOutputs {
    /// The evaluation (print `eval.to_markdown()`).
    pub eval: EvalReport,
    /// `report.md`.
    pub report: PathBuf,
    /// Every picture written.
    pub pictures: Vec<PathBuf>,
}

/// Half the side of the zoom windows, metres: wide enough for a parked car and the
/// curb on either side of it, or an intersection corner of up to 10 m radius.
pub const ZOOM_HALF_SIZE_M: f64 = 9.0;

fn caption_of(name: &str) -> &'static str {
    match name {
        "curb_cut" => "Zoom: a curb cut",
        "intersection" => "Zoom: an intersection corner",
        "bus_bay" => "Zoom: the bus bay",
        "occlusion" => "Zoom: a stretch the scanner could not see (a parked car)",
        _ => "Zoom",
    }
}

/// Evaluates `inp.extracted` against `inp.reference`, writes `eval.json`, the pictures
/// (`overview.png`, one `zoom_<name>.png` per window of interest, `cross_section.png`) and
/// `report.md` into `out_dir` (created if missing).
pub fn write_demo_outputs(out_dir: &Path, inp: &DemoInputs) -> Result<DemoOutputs, ReportError> {
    let io = |p: &Path, e: std::io::Error| ReportError::Io {
        path: p.display().to_string(),
        what: e.to_string(),
    };
    std::fs::create_dir_all(out_dir).map_err(|e| io(out_dir, e))?;
    let mut timings = inp.timings.clone();

    let t = Instant::now();
    let eval = evaluate(inp.reference, inp.extracted, &EvalParams::default())?;
    timings.push(("evaluation".into(), t.elapsed().as_secs_f64()));
    let json = out_dir.join("eval.json");
    std::fs::write(&json, eval.to_json()).map_err(|e| io(&json, e))?;

    let t = Instant::now();
    let mut pictures = Vec::new();
    let mut shown = Vec::new();
    let mut view = TopView::new(
        format!(
            "scene {} — {} edges (black) on the reference (red)",
            inp.scene, inp.method
        ),
        inp.cloud,
        inp.reference,
        inp.extracted,
    );
    view.trajectory = inp.trajectory_xy;
    let p = out_dir.join("overview.png");
    top_view_png(&p, &view)?;
    pictures.push(p);
    shown.push(Picture {
        file: "overview.png".into(),
        caption: "Overview: points coloured by height, reference and extracted edges".into(),
    });

    let mut windows: Vec<(String, String, Window)> =
        windows_of_interest(inp.reference, ZOOM_HALF_SIZE_M)
            .into_iter()
            .map(|(n, w)| (n.clone(), caption_of(&n).to_string(), w))
            .collect();
    // A parked car the caller knows of shows the same as the occlusion found from the
    // reference; keep one.
    if inp
        .extra_windows
        .iter()
        .any(|w| w.0.starts_with("parked_car"))
    {
        windows.retain(|w| w.0 != "occlusion");
    }
    windows.extend(inp.extra_windows.iter().cloned());
    for (name, caption, w) in windows {
        let file = format!("zoom_{name}.png");
        let mut v = view.clone();
        v.title = caption.clone();
        v.window = Some(w);
        v.width_px = 1100;
        let p = out_dir.join(&file);
        top_view_png(&p, &v)?;
        pictures.push(p);
        shown.push(Picture { file, caption });
    }
    if let Some(cs) = &inp.cross_section {
        let p = out_dir.join("cross_section.png");
        cross_section_png(&p, cs)?;
        pictures.push(p);
        shown.push(Picture {
            file: "cross_section.png".into(),
            caption: "A scanline and its bend angles before and after smoothing".into(),
        });
    }
    timings.push(("pictures".into(), t.elapsed().as_secs_f64()));

    let mut files = inp.files.clone();
    files.push(("eval.json".into(), "the metrics as JSON".into()));
    files.extend(shown.iter().map(|p| (p.file.clone(), p.caption.clone())));
    let report = DemoReport {
        scene: inp.scene.clone(),
        method: inp.method.clone(),
        command: inp.command.clone(),
        eval: &eval,
        pictures: shown,
        facts: inp.facts.clone(),
        parameters: inp.parameters.clone(),
        timings,
        files,
    };
    let path = out_dir.join("report.md");
    write_report(&path, &report)?;
    Ok(DemoOutputs {
        eval,
        report: path,
        pictures,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Category, Side};

    fn line(pts: &[(f64, f64)], side: Side, cat: Option<Category>) -> EdgeLine {
        EdgeLine {
            points: pts
                .iter()
                .map(|&(x, y)| [600_000.0 + x, 3_000_000.0 + y, 5.0])
                .collect(),
            side,
            category: cat,
            method: None,
            curb_height_m: None,
            detail: None,
        }
    }

    #[test]
    fn demo_outputs_have_report_pictures_and_json() {
        // A 40 m street: left curb with a curb cut, right curb; ground grid points.
        let refs = vec![
            line(&[(0.0, 4.0), (20.0, 4.0)], Side::Left, Some(Category::Curb)),
            line(
                &[(20.0, 4.0), (26.0, 4.0)],
                Side::Left,
                Some(Category::CurbCut),
            ),
            line(
                &[(26.0, 4.0), (40.0, 4.0)],
                Side::Left,
                Some(Category::Curb),
            ),
            line(
                &[(0.0, -4.0), (40.0, -4.0)],
                Side::Right,
                Some(Category::Curb),
            ),
        ];
        let ext = vec![line(&[(0.0, 4.01), (30.0, 4.01)], Side::Left, None)];
        let (mut x, mut y, mut z) = (Vec::new(), Vec::new(), Vec::new());
        for i in 0..200 {
            for j in 0..60 {
                let (px, py) = (i as f64 * 0.2, -6.0 + j as f64 * 0.2);
                x.push(600_000.0 + px);
                y.push(3_000_000.0 + py);
                z.push(if py.abs() > 4.0 { 5.15 } else { 5.0 });
            }
        }
        let traj = [[600_000.0, 3_000_000.0], [600_040.0, 3_000_000.0]];
        let inp = DemoInputs {
            scene: "unit".into(),
            method: "bend".into(),
            command: "curbtrace demo --out X".into(),
            cloud: Cloud {
                x: &x,
                y: &y,
                z: &z,
            },
            trajectory_xy: &traj,
            reference: &refs,
            extracted: &ext,
            cross_section: None,
            extra_windows: vec![],
            facts: vec![("points".into(), x.len().to_string())],
            parameters: vec![("d_b_m".into(), "0.1".into())],
            timings: vec![("simulate".into(), 1.5)],
            files: vec![("edges.geojson".into(), "extracted edges".into())],
        };
        // CURBTRACE_PLOT_DIR keeps the outputs for a look.
        let tmp = tempfile::tempdir().unwrap();
        let dir = std::env::var_os("CURBTRACE_PLOT_DIR")
            .map(|d| PathBuf::from(d).join("demo"))
            .unwrap_or_else(|| tmp.path().to_path_buf());
        let out = write_demo_outputs(&dir, &inp).unwrap();
        // Left 40 m: 30 m + 50 mm matched; right 40 m unmatched.
        let c = out.eval.total.completeness_pct.unwrap();
        assert!((c - 30.05 / 80.0 * 100.0).abs() < 0.02, "{c}");
        let names: Vec<String> = out
            .pictures
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names, ["overview.png", "zoom_curb_cut.png"]);
        for p in &out.pictures {
            assert!(std::fs::metadata(p).unwrap().len() > 10_000, "{p:?}");
        }
        let md = std::fs::read_to_string(&out.report).unwrap();
        for needle in [
            "# curbtrace demo — scene `unit`, method `bend`",
            "![Overview",
            "(zoom_curb_cut.png)",
            "| Completeness [%]",
            "| d_b_m | 0.1 |",
            "| simulate | 1.50 |",
            "| evaluation |",
            "[`eval.json`](eval.json)",
            "[`edges.geojson`](edges.geojson)",
            "completeness 37.6 %",
        ] {
            assert!(md.contains(needle), "missing {needle:?} in\n{md}");
        }
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("eval.json")).unwrap()).unwrap();
        assert_eq!(json["sides"][0]["side"], "left");
    }

    #[test]
    fn unwritable_directory_is_an_error_naming_it() {
        let inp = DemoInputs {
            scene: "x".into(),
            method: "bend".into(),
            command: String::new(),
            cloud: Cloud {
                x: &[],
                y: &[],
                z: &[],
            },
            trajectory_xy: &[],
            reference: &[],
            extracted: &[],
            cross_section: None,
            extra_windows: vec![],
            facts: vec![],
            parameters: vec![],
            timings: vec![],
            files: vec![],
        };
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("a-file");
        std::fs::write(&file, b"x").unwrap();
        let err = write_demo_outputs(&file.join("sub"), &inp)
            .unwrap_err()
            .to_string();
        assert!(err.contains("a-file"), "{err}");
    }

    /// Draws the demo's pictures for a simulated scene, with the reference itself, shifted
    /// 20 mm and with every fifth metre left out, standing in for the extraction. For looking
    /// at the pictures: `CURBTRACE_PLOT_DIR=/tmp/x CURBTRACE_SCENE=kawasaki cargo test -p
    /// curbtrace-host-sim --release pictures_of_a_simulated_scene -- --ignored`.
    #[test]
    #[ignore = "slow; for looking at the pictures of a simulated scene"]
    fn pictures_of_a_simulated_scene() {
        use crate::simulate::{scene_by_name, simulate};
        let name = std::env::var("CURBTRACE_SCENE").unwrap_or_else(|_| "tiny".into());
        let spec = scene_by_name(&name).unwrap();
        let t = Instant::now();
        let sim = simulate(&spec, 1, None, false).unwrap();
        let sim_s = t.elapsed().as_secs_f64();
        let [x, y, z] = sim.world_columns();
        let traj = sim.world_trajectory_xy();
        let ext: Vec<EdgeLine> = sim
            .reference
            .iter()
            .flat_map(|l| {
                let pts: Vec<[f64; 3]> =
                    l.points.iter().map(|p| [p[0] + 0.02, p[1], p[2]]).collect();
                pts.chunks(5)
                    .enumerate()
                    .filter(|(i, _)| i % 5 != 4)
                    .map(|(_, c)| EdgeLine {
                        points: c.to_vec(),
                        ..l.clone()
                    })
                    .collect::<Vec<_>>()
            })
            .collect();
        let tmp = tempfile::tempdir().unwrap();
        let dir = std::env::var_os("CURBTRACE_PLOT_DIR")
            .map(|d| PathBuf::from(d).join(&name))
            .unwrap_or_else(|| tmp.path().to_path_buf());
        let inp = DemoInputs {
            scene: name.clone(),
            method: "reference-shifted".into(),
            command: "cargo test pictures_of_a_simulated_scene".into(),
            cloud: Cloud {
                x: &x,
                y: &y,
                z: &z,
            },
            trajectory_xy: &traj,
            reference: &sim.reference,
            extracted: &ext,
            cross_section: None,
            extra_windows: vec![],
            facts: vec![("points".into(), x.len().to_string())],
            parameters: vec![],
            timings: vec![("simulate".into(), sim_s)],
            files: vec![],
        };
        let out = write_demo_outputs(&dir, &inp).unwrap();
        eprintln!("{}", out.eval.to_markdown());
        eprintln!("{:?}", out.pictures);
    }
}
