//! End-to-end tests of the `microraster` binary: outputs, invariance over
//! threads and strips, and one-line errors for bad input.

use std::path::PathBuf;
use std::process::{Command, Output};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_microraster"))
}

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("microraster-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn run(args: &[&str]) -> Output {
    bin().args(args).output().expect("run microraster")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn checksum(extra: &[&str]) -> String {
    let out = tmp("sum.png");
    let mut args = vec!["render", "--checksum", "--out", out.to_str().unwrap()];
    args.extend_from_slice(extra);
    let o = run(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    stdout(&o).trim().to_string()
}

#[test]
fn default_render_writes_the_cubes_png() {
    let out = tmp("cubes.png");
    let o = run(&["render", "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&out).unwrap()));
    let reader = decoder.read_info().unwrap();
    let info = reader.info();
    assert_eq!((info.width, info.height), (800, 600));
}

#[test]
fn output_is_identical_for_any_threads_and_strip_rows() {
    for depth in ["u16", "u32", "none"] {
        let base = checksum(&["--threads", "1", "--strip-rows", "600", "--depth", depth]);
        for (t, r) in [("2", "16"), ("2", "1"), ("3", "7"), ("1", "5"), ("4", "64")] {
            let other = checksum(&["--threads", t, "--strip-rows", r, "--depth", depth]);
            assert_eq!(base, other, "depth {depth} threads {t} strip rows {r}");
        }
    }
}

#[test]
fn id_and_depth_outputs_have_the_right_size() {
    let (img, ids, depth) = (tmp("i.png"), tmp("ids.png"), tmp("depth.raw"));
    let o = run(&[
        "render",
        "--size",
        "64x48",
        "--out",
        img.to_str().unwrap(),
        "--id-out",
        ids.to_str().unwrap(),
        "--depth-out",
        depth.to_str().unwrap(),
        "--depth",
        "u16",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(std::fs::metadata(&depth).unwrap().len(), 64 * 48 * 2);
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&ids).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgba);
    // Every id is 0 (background) or 1..=48 (a cube triangle).
    let ids: Vec<u32> = buf[..info.buffer_size()]
        .chunks(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    assert!(ids.iter().all(|&i| i <= 48));
    assert!(ids.iter().any(|&i| i > 0));
}

#[test]
fn clip_tris_wedge_behind_the_eye_covers_640_pixels() {
    let file = tmp("wedge.txt");
    std::fs::write(
        &file,
        "# w <= 0: the wedge below y = -0.5\n-0.5 -0.5 0 1  0.5 -0.5 0 1  0 -0.5 0 -1  255 0 0\n",
    )
    .unwrap();
    let out = tmp("wedge.png");
    let o = run(&[
        "render",
        "--clip-tris",
        file.to_str().unwrap(),
        "--size",
        "64x64",
        "--cull",
        "none",
        "--stats",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let s = stdout(&o);
    assert!(s.contains("\"pixels_written\": 640"), "{s}");
}

#[test]
fn bad_input_gives_one_line_error_and_nonzero_exit() {
    let bad_tris = tmp("bad.txt");
    std::fs::write(&bad_tris, "1 2 3\n").unwrap();
    let cases: Vec<Vec<String>> = vec![
        vec!["render".into(), "--size".into(), "0x5".into()],
        vec!["render".into(), "--out".into(), "x.bmp".into()],
        vec!["render".into(), "--threads".into(), "0".into()],
        vec![
            "render".into(),
            "--obj".into(),
            "/nonexistent/mesh.obj".into(),
        ],
        vec![
            "render".into(),
            "--clip-tris".into(),
            bad_tris.to_str().unwrap().into(),
        ],
        vec!["render".into(), "--cull".into(), "sideways".into()],
        vec!["render".into(), "--size".into(), "20000x10".into()],
    ];
    for args in cases {
        let o = bin().args(&args).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{args:?} succeeded");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert!(!err.trim().is_empty(), "{args:?}: no message");
    }
}

#[test]
fn nonfinite_clip_tris_are_counted_not_fatal() {
    let file = tmp("nan.txt");
    std::fs::write(
        &file,
        "nan 0 0 1  1 0 0 1  0 1 0 1\ninf 0 0 1 1 0 0 1 0 1 0 1\n",
    )
    .unwrap();
    let out = tmp("nan.png");
    let o = run(&[
        "render",
        "--clip-tris",
        file.to_str().unwrap(),
        "--stats",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success());
    assert!(
        stdout(&o).contains("\"rejected_nonfinite\": 2"),
        "{}",
        stdout(&o)
    );
}
