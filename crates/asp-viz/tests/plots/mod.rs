//! Plots: SVG that parses with one marker per point and the front's staircase, PNG of the
//! right size, clear errors on bad input.

use asp_search::report::{ParetoEntry, PlanReport};
use asp_viz::plot::{is_bench_csv, read_bench, read_front, read_trace, staircase, write_front, write_traces, TraceAxis};
use std::path::Path;

fn front_file(dir: &Path, points: &[Vec<f64>]) -> std::path::PathBuf {
    let mut report: PlanReport = crate::common::planned(asp_geom::fixtures::tube()).report;
    report.pareto_front = Some(points.iter().map(|p| ParetoEntry { objectives: p.clone(), disassembly_sequence: vec![1, 2, 3] }).collect());
    let path = dir.join("front.json");
    std::fs::write(&path, serde_json::to_string(&report).unwrap()).unwrap();
    path
}

fn circles(svg: &str) -> usize {
    let doc = roxmltree::Document::parse(svg).unwrap();
    doc.descendants().filter(|n| n.has_tag_name("circle")).count()
}

fn png_size(path: &Path) -> (u32, u32) {
    let reader = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap())).read_info().unwrap();
    (reader.info().width, reader.info().height)
}

#[test]
fn the_staircase_keeps_the_non_dominated_points() {
    let pts = vec![vec![1.0, 5.0], vec![2.0, 4.0], vec![1.5, 3.0], vec![3.0, 1.0], vec![0.5, 5.0]];
    assert_eq!(staircase(&pts, 0, 1), vec![(1.0, 5.0), (2.0, 4.0), (3.0, 1.0)]);
}

#[test]
fn fronts_plot_one_marker_per_point_and_pairwise_panels() {
    let dir = tempfile::tempdir().unwrap();
    let two = front_file(dir.path(), &[vec![1.0, 5.0], vec![2.0, 4.0], vec![3.0, 1.0], vec![4.0, 0.5]]);
    let front = read_front(&two).unwrap();
    assert_eq!(front.objectives, ["objective 1", "objective 2"]);
    let svg = dir.path().join("front.svg");
    assert_eq!(write_front(&svg, &front).unwrap(), vec![4]);
    let text = std::fs::read_to_string(&svg).unwrap();
    assert_eq!(circles(&text), 4);
    // the staircase: 4 corners, 3 steps down and right -> 7 points in one polyline
    let doc = roxmltree::Document::parse(&text).unwrap();
    let longest = doc
        .descendants()
        .filter(|n| n.has_tag_name("polyline"))
        .map(|n| n.attribute("points").unwrap_or("").split_whitespace().count())
        .max()
        .unwrap();
    assert_eq!(longest, 7);

    let three = front_file(dir.path(), &[vec![1.0, 5.0, 2.0], vec![2.0, 4.0, 1.0], vec![3.0, 1.0, 3.0]]);
    let front = read_front(&three).unwrap();
    let svg = dir.path().join("front3.svg");
    assert_eq!(write_front(&svg, &front).unwrap(), vec![3, 3, 3]);
    assert_eq!(circles(&std::fs::read_to_string(&svg).unwrap()), 9, "three panels of three points");
    let png = dir.path().join("front3.png");
    write_front(&png, &front).unwrap();
    assert_eq!(png_size(&png), (3 * 560, 480));
}

#[test]
fn traces_plot_every_row_of_every_file() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("run-a.csv");
    let b = dir.path().join("run-b.csv");
    std::fs::write(
        &a,
        "episode,iterations,seconds,value,front_size\n1,10,0.01,0.5,2\n5,50,0.05,0.7,3\n9,90,0.09,0.8,3\n12,120,0.12,0.8,3\n",
    )
    .unwrap();
    std::fs::write(&b, "episode,iterations,seconds,value,front_size\n1,10,0.02,0.4,1\n7,70,0.08,0.9,4\n10,100,0.1,0.9,4\n").unwrap();
    let traces = vec![read_trace(&a).unwrap(), read_trace(&b).unwrap()];
    assert_eq!(traces[0].label, "run-a");
    let svg = dir.path().join("hv.svg");
    write_traces(&svg, &traces, TraceAxis::Seconds).unwrap();
    let text = std::fs::read_to_string(&svg).unwrap();
    assert_eq!(circles(&text), 7);
    assert!(text.contains("run-a") && text.contains("run-b"), "the legend names both files");
    let png = dir.path().join("hv.png");
    write_traces(&png, &traces, TraceAxis::Episodes).unwrap();
    assert_eq!(png_size(&png), (900, 560));
}

/// `asp bench mcts --csv`: one line per setting, each model's values divided by the best any
/// setting reached on it, averaged over the models.
#[test]
fn a_bench_csv_plots_each_setting_relative_to_the_best() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("bench.csv");
    std::fs::write(
        &csv,
        "model,setting,seconds,mean,std,episodes\n\
         a,vanilla,10,80,0,1000\na,vanilla,60,100,0,1000\na,pretrained,10,50,0,20\na,pretrained,60,90,0,20\n\
         b,vanilla,10,4,0,3000\nb,vanilla,60,4,0,3000\nb,pretrained,10,2,0,40\nb,pretrained,60,5,0,40\n",
    )
    .unwrap();
    assert!(is_bench_csv(&csv).unwrap());
    let traces = read_bench(&csv).unwrap();
    let labels: Vec<&str> = traces.iter().map(|t| t.label.as_str()).collect();
    assert_eq!(labels, ["vanilla", "pretrained"]);
    let close = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12);
    assert_eq!(traces[0].seconds, [10.0, 60.0]);
    // model a's best is 100 (vanilla at 60 s), b's 5 (pretrained at 60 s)
    assert!(close(&traces[0].values, &[(0.8 + 0.8) / 2.0, (1.0 + 0.8) / 2.0]), "{:?}", traces[0].values);
    assert!(close(&traces[1].values, &[(0.5 + 0.4) / 2.0, (0.9 + 1.0) / 2.0]), "{:?}", traces[1].values);
    assert!(close(&traces[1].episodes, &[30.0, 30.0]));
    let svg = dir.path().join("bench.svg");
    write_traces(&svg, &traces, TraceAxis::Seconds).unwrap();
    let text = std::fs::read_to_string(&svg).unwrap();
    assert_eq!(circles(&text), 4);
    assert!(text.contains("fraction of the best"), "the axis says the values are relative");
    // a trace CSV is not a bench CSV; a bench CSV without a positive value is refused
    let trace = dir.path().join("t.csv");
    std::fs::write(&trace, "episode,iterations,seconds,value,front_size\n1,1,0.1,1,1\n").unwrap();
    assert!(!is_bench_csv(&trace).unwrap());
    std::fs::write(&csv, "model,setting,seconds,mean,std,episodes\nc,vanilla,10,0,0,5\n").unwrap();
    let e = read_bench(&csv).unwrap_err().to_string();
    assert!(e.contains("bench.csv") && e.contains("model c"), "{e}");
}

#[test]
fn bad_inputs_are_one_line_errors_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("bad.csv");
    std::fs::write(&csv, "episode,seconds\n1,2\n").unwrap();
    let e = read_trace(&csv).unwrap_err().to_string();
    assert!(e.contains("bad.csv") && e.contains("no column 'value'"), "{e}");
    std::fs::write(&csv, "episode,iterations,seconds,value,front_size\n1,1,x,1,1\n").unwrap();
    let e = read_trace(&csv).unwrap_err().to_string();
    assert!(e.contains("row 2") && !e.contains('\n'), "{e}");
    let plan = dir.path().join("plain.json");
    std::fs::write(&plan, serde_json::to_string(&crate::common::planned(asp_geom::fixtures::tube()).report).unwrap()).unwrap();
    let e = read_front(&plan).unwrap_err().to_string();
    assert!(e.contains("plain.json") && e.contains("pareto_front"), "{e}");
    let e = write_front(
        &dir.path().join("x.gif"),
        &asp_viz::plot::Front { objectives: vec!["a".into(), "b".into()], points: vec![vec![1.0, 2.0]] },
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("x.gif"), "{e}");
}
