//! End-to-end tests of `microraster bench`: it runs on tiny frames and
//! prints valid JSON with the promised fields (not timed tests: the numbers
//! are only checked for being there and positive).

use serde_json::Value;
use std::process::{Command, Output};

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_microraster"))
        .args(args)
        .output()
        .expect("run microraster")
}

fn bench_json(args: &[&str]) -> Value {
    let mut a = vec!["bench"];
    a.extend_from_slice(args);
    let o = run(&a);
    assert!(
        o.status.success(),
        "{a:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    serde_json::from_slice(&o.stdout).unwrap_or_else(|e| {
        panic!(
            "{a:?}: not JSON ({e}): {}",
            String::from_utf8_lossy(&o.stdout)
        )
    })
}

fn positive(v: &Value, key: &str) -> f64 {
    let x = v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("{key} missing in {v}"));
    assert!(x > 0.0 && x.is_finite(), "{key} = {x}");
    x
}

#[test]
fn sphere_two_frames_prints_valid_json() {
    let v = bench_json(&[
        "--scene", "sphere", "--size", "48x64", "--frames", "2", "--warmup", "1",
    ]);
    assert_eq!(v["scene"], "sphere");
    assert_eq!(v["size"], "48x64");
    assert_eq!(v["triangles"], 20_000);
    assert_eq!(v["threads"], 1);
    assert_eq!(v["frames"], 2);
    assert_eq!(
        (v["depth"].as_str(), v["color"].as_str()),
        (Some("u16"), Some("rgb565"))
    );
    for key in [
        "median_ms",
        "min_ms",
        "mean_ms",
        "triangles_per_s",
        "shaded_pixels_per_s",
    ] {
        positive(&v, key);
    }
    assert!(v["min_ms"].as_f64() <= v["median_ms"].as_f64());
    for key in ["setup_median_ms", "raster_median_ms"] {
        positive(&v["stages"], key);
    }
    assert_eq!(v["counters"]["submitted"], 20_000);
    let table = &v["split"]["table"];
    for key in [
        "transform_ms",
        "cull_clip_setup_ms",
        "binning_ms",
        "traversal_ms",
    ] {
        assert!(table[key].is_number(), "{key} in {table}");
    }
}

#[test]
fn thread_list_peers_and_floor() {
    // The peers only with the `peers` feature (tests/cli.rs checks the
    // error without it).
    let peers = cfg!(feature = "peers");
    let mut args = vec![
        "--scene",
        "cubes",
        "--size",
        "80x60",
        "--frames",
        "2",
        "--warmup",
        "0",
        "--threads",
        "1,2",
        "--floor",
        "--no-split",
        "--compact",
    ];
    if peers {
        args.push("--peers");
    }
    let v = bench_json(&args);
    assert!(v.get("split").is_none());
    let s = &v["scaling"];
    assert_eq!(s["identical_output"], true);
    assert_eq!(s["1"]["speedup"], 1.0);
    positive(&s["2"], "speedup");
    assert_eq!(s["1"]["checksum"], v["checksum"]);
    if peers {
        let p = &v["peers"];
        positive(p, "euc_over_microraster");
        positive(&p["embedded_graphics_2d"], "eg_over_microraster");
        assert_eq!(
            p["euc"]["covered_pixels"], p["microraster"]["covered_pixels"],
            "euc and microraster cover the same pixels of the cubes"
        );
    } else {
        assert!(v.get("peers").is_none());
    }
    let f = &v["floor"];
    positive(f, "floor_ms");
    positive(f, "frame_over_floor");
    assert_eq!(f["bytes_per_frame"], 80 * 60 * 8);
}

#[test]
fn quad_reports_the_memory_floor() {
    let v = bench_json(&[
        "--scene",
        "quad",
        "--size",
        "64x32",
        "--frames",
        "3",
        "--threads",
        "1",
    ]);
    assert_eq!(v["triangles"], 2);
    assert_eq!(v["pixels_written"], 64 * 32);
    positive(&v["floor"], "draw_only_over_floor");
}

#[test]
fn bench_checksum_matches_render() {
    // A static scene: every frame is the frame `render` draws.
    let v = bench_json(&[
        "--scene",
        "cubes",
        "--size",
        "120x90",
        "--frames",
        "1",
        "--warmup",
        "0",
        "--no-split",
    ]);
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("bench.png");
    let o = run(&[
        "render",
        "--scene",
        "cubes",
        "--size",
        "120x90",
        "--checksum",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(
        v["checksum"].as_str(),
        Some(String::from_utf8_lossy(&o.stdout).trim())
    );
}

#[test]
fn render_knows_the_bench_scenes() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sphere.png");
    let o = run(&[
        "render",
        "--scene",
        "sphere",
        "--size",
        "60x80",
        "--depth",
        "u16",
        "--stats",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: Value = serde_json::from_slice(&o.stdout).expect("stats JSON");
    assert_eq!(v["counters"]["submitted"], 20_000);
}

#[test]
fn bad_input_is_one_line_and_fails() {
    let o = run(&["bench", "--obj", "/nonexistent/mesh.obj", "--frames", "1"]);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(o.stdout.is_empty());
    let o = run(&["bench", "--threads", "0"]);
    assert_eq!(o.status.code(), Some(2));
}
