//! End-to-end tests of the `microraster` binary: outputs, invariance over
//! threads and strips, one-line errors for bad input, and "the CLI never
//! lies": every option either acts or is refused, every empty or lossy
//! render says so, and outputs are written all or nothing. Each test makes
//! its own temporary directory; fixtures are in `tests/data/` or written
//! here.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_microraster"))
}

/// A directory shared by the tests that only need scratch files, removed
/// when the process ends (tests that check a directory's contents make
/// their own).
fn scratch() -> &'static Path {
    static DIR: OnceLock<tempfile::TempDir> = OnceLock::new();
    DIR.get_or_init(|| tempfile::tempdir().unwrap()).path()
}

fn tmp(name: &str) -> PathBuf {
    scratch().join(name)
}

fn data(name: &str) -> String {
    format!("{}/tests/data/{name}", env!("CARGO_MANIFEST_DIR"))
}

const TEAPOT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../assets/models/teapot.obj");

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn ok(args: &[&str]) -> Output {
    let o = run(args);
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    o
}

fn fails(args: &[&str]) -> String {
    let o = run(args);
    assert_eq!(o.status.code(), Some(1), "{args:?}: {}", stderr(&o));
    let e = stderr(&o);
    assert!(e.starts_with("microraster: error: "), "{args:?}: {e}");
    assert_eq!(e.trim().lines().count(), 1, "{args:?}: {e}");
    e
}

fn stats(args: &[&str]) -> (Value, String) {
    let out = tmp(&format!(
        "stats-{}.png",
        args.join("_").replace(['/', '.', ','], "-")
    ));
    let mut a = vec!["render", "--stats", "--out", out.to_str().unwrap()];
    a.extend_from_slice(args);
    let o = ok(&a);
    let v: Value = serde_json::from_slice(&o.stdout).expect("one JSON document");
    (v, stderr(&o))
}

fn run(args: &[&str]) -> Output {
    bin().args(args).output().expect("run microraster")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn checksum(extra: &[&str]) -> String {
    let out = tmp(&format!(
        "sum-{}.png",
        extra.join("_").replace(['/', '.', ','], "-")
    ));
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

/// `--mode clipless`: the same image, ids and depth for any thread count
/// and strip height, close to the clipping mode's (the quantizations
/// differ by a hair at edges), for the built-in scenes and a lit model.
#[test]
fn clipless_mode_renders_the_same_frame_for_any_split() {
    for scene in ["cubes", "sphere"] {
        let base = outputs(
            &format!("clipless-{scene}-1"),
            &[
                "--scene",
                scene,
                "--mode",
                "clipless",
                "--threads",
                "1",
                "--strip-rows",
                "600",
            ],
        );
        for (t, r) in [("2", "16"), ("3", "7"), ("2", "1")] {
            let other = outputs(
                &format!("clipless-{scene}-{t}-{r}"),
                &[
                    "--scene",
                    scene,
                    "--mode",
                    "clipless",
                    "--threads",
                    t,
                    "--strip-rows",
                    r,
                ],
            );
            assert!(base == other, "{scene}: threads {t} strip rows {r} differ");
        }
        let (clipless, _) = stats(&["--scene", scene, "--mode", "clipless"]);
        let (clipping, _) = stats(&["--scene", scene]);
        let px = |v: &Value| v["counters"]["pixels_written"].as_u64().unwrap() as f64;
        assert!((px(&clipless) / px(&clipping) - 1.0).abs() < 0.002);
    }
    // A lit, textured model (Phong by default): strip renderers per strip
    // or tile with the shader, the same outputs for any split, coverage
    // within 0.2 % of the clipping mode's.
    let spot = concat!(env!("CARGO_MANIFEST_DIR"), "/../assets/models/spot.obj");
    let obj = |extra: &[&'static str]| {
        let mut a = vec!["--obj", spot, "--size", "200x150", "--mode", "clipless"];
        a.extend_from_slice(extra);
        a
    };
    let one = outputs("clipless-spot-1", &obj(&["--threads", "1"]));
    for (tag, extra) in [
        ("2-7", &["--threads", "2", "--strip-rows", "7"][..]),
        ("tile", &["--threads", "2", "--tile", "32x32"][..]),
    ] {
        let other = outputs(&format!("clipless-spot-{tag}"), &obj(extra));
        assert!(one == other, "Spot clipless {tag} differs");
    }
    let (clipless, _) = stats(&obj(&[]));
    let (clipping, _) = stats(&["--obj", spot, "--size", "200x150"]);
    let px = |v: &Value| v["counters"]["pixels_written"].as_u64().unwrap() as f64;
    assert!(px(&clipping) > 4000.0);
    assert!((px(&clipless) / px(&clipping) - 1.0).abs() < 0.002);
    let strips = outputs("clipless-strips", &["--mode", "clipless", "--threads", "2"]);
    for tile in ["32x32", "7x5", "800x3"] {
        let tiles = outputs(
            &format!("clipless-tile-{tile}"),
            &["--mode", "clipless", "--tile", tile, "--threads", "2"],
        );
        assert!(tiles == strips, "tiles of {tile} differ");
    }
}

/// `--depth-kind inv-w`: 1/w depth, reversed (larger is nearer, cleared
/// to 0), the same image as window z where no two surfaces are that close,
/// the same outputs for any split, in both modes; errors where it cannot
/// apply.
#[test]
fn inv_w_depth_kind() {
    for mode in ["clipping", "clipless"] {
        let base = outputs(
            &format!("invw-{mode}-1"),
            &[
                "--mode",
                mode,
                "--depth-kind",
                "inv-w",
                "--depth",
                "u32",
                "--threads",
                "1",
            ],
        );
        let other = outputs(
            &format!("invw-{mode}-2"),
            &[
                "--mode",
                mode,
                "--depth-kind",
                "inv-w",
                "--depth",
                "u32",
                "--threads",
                "2",
                "--strip-rows",
                "5",
            ],
        );
        assert!(base == other, "{mode}: the split changed the outputs");
        let z = outputs(&format!("z-{mode}"), &["--mode", mode, "--depth", "u32"]);
        let d = |b: &[u8]| -> Vec<u32> {
            b.chunks_exact(4)
                .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                .collect()
        };
        let (inv, zz) = (d(&base[2]), d(&z[2]));
        // Background: 0 against the far plane's u32::MAX.
        assert_eq!(
            inv.iter().filter(|&&v| v == 0).count(),
            zz.iter().filter(|&&v| v == u32::MAX).count()
        );
        // Nearer is larger: of any two drawn pixels, the order of 1/w is the
        // reverse of the order of window z (ties aside).
        let drawn: Vec<usize> = (0..inv.len())
            .filter(|&i| inv[i] != 0)
            .step_by(97)
            .collect();
        assert!(drawn.len() > 500);
        for w in drawn.windows(2) {
            let (a, b) = (w[0], w[1]);
            if zz[a] < zz[b] {
                assert!(inv[a] >= inv[b], "{mode}: pixels {a} {b}");
            }
        }
    }
    let o = tmp("invw.png");
    let o = o.to_str().unwrap();
    let e = fails(&[
        "render",
        "--depth-kind",
        "inv-w",
        "--depth",
        "none",
        "--out",
        o,
    ]);
    assert!(e.contains("depth buffer"), "{e}");
    // A lit model too (set up once, Phong and texture), into `u32` and
    // `f32` buffers: the same coverage as window z, nearer larger, and the
    // `f32` values the `u32` ones to 24 significant bits.
    let spot = concat!(env!("CARGO_MANIFEST_DIR"), "/../assets/models/spot.obj");
    let args = |kind: &'static str, depth: &'static str| {
        vec![
            "--obj",
            spot,
            "--size",
            "160x120",
            "--depth-kind",
            kind,
            "--depth",
            depth,
        ]
    };
    let inv = outputs("spot-invw", &args("inv-w", "u32"));
    let inv_f = outputs("spot-invw-f32", &args("inv-w", "f32"));
    let z = outputs("spot-z", &args("z", "u32"));
    let u = |b: &[u8]| -> Vec<u32> {
        b.chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect()
    };
    let f = |b: &[u8]| -> Vec<f32> {
        b.chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect()
    };
    let (inv_d, inv_fd, z_d) = (u(&inv[2]), f(&inv_f[2]), u(&z[2]));
    let drawn = inv_d.iter().filter(|&&v| v != 0).count();
    assert!(drawn > 2000, "{drawn}");
    assert_eq!(drawn, z_d.iter().filter(|&&v| v != u32::MAX).count());
    for (&a, &b) in inv_d.iter().zip(&inv_fd) {
        let b = b as f64 * 4_294_967_296.0;
        assert!(
            (a as f64 - b).abs() <= (a as f64 / 8_388_608.0).max(1.0),
            "{a} {b}"
        );
    }
}

/// The colour, id and depth outputs of `render` with `extra` arguments.
fn outputs(tag: &str, extra: &[&str]) -> [Vec<u8>; 3] {
    let (img, ids, depth) = (
        tmp(&format!("{tag}.png")),
        tmp(&format!("{tag}-ids.png")),
        tmp(&format!("{tag}-depth.raw")),
    );
    let mut args = vec![
        "render",
        "--out",
        img.to_str().unwrap(),
        "--id-out",
        ids.to_str().unwrap(),
        "--depth-out",
        depth.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let o = run(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    [img, ids, depth].map(|p| std::fs::read(p).unwrap())
}

/// `--tile WxH` draws tiles instead of strips: the same image, ids and
/// depth, for the built-in scenes and a lit, textured model, at any tile
/// size and thread count.
#[test]
fn tiles_give_the_output_of_strips() {
    let spot = concat!(env!("CARGO_MANIFEST_DIR"), "/../assets/models/spot.obj");
    for (name, scene) in [
        ("cubes", vec!["--size", "203x150"]),
        ("spot", vec!["--obj", spot, "--size", "160x120"]),
    ] {
        for depth in ["u16", "u32"] {
            let mut base_args = scene.clone();
            base_args.extend(["--depth", depth]);
            let mut one = base_args.clone();
            one.extend(["--threads", "1"]);
            let base = outputs(&format!("tiles-{name}-{depth}"), &one);
            for (t, tile) in [("1", "32x32"), ("2", "7x5"), ("3", "64x16"), ("2", "1x200")] {
                let mut a = base_args.clone();
                a.extend(["--threads", t, "--tile", tile]);
                let tag = format!("tiles-{name}-{depth}-{t}-{}", tile.replace('x', "_"));
                assert!(
                    outputs(&tag, &a) == base,
                    "{name}: depth {depth}, {t} threads, tiles {tile}"
                );
            }
        }
    }
    // Without a depth buffer too (tiles narrower than the image used to
    // slice an empty depth tile and panic).
    let image = |tag: &str, extra: &[&str]| {
        let img = tmp(&format!("{tag}.png"));
        let mut args = vec!["render", "--out", img.to_str().unwrap(), "--depth", "none"];
        args.extend_from_slice(extra);
        let o = run(&args);
        assert!(o.status.success(), "{extra:?}: {}", stderr(&o));
        std::fs::read(img).unwrap()
    };
    let base = image("tiles-nodepth", &["--size", "203x150", "--threads", "1"]);
    for (t, tile) in [("1", "32x32"), ("2", "7x5"), ("2", "1x200")] {
        let tag = format!("tiles-nodepth-{t}-{}", tile.replace('x', "_"));
        let a = ["--size", "203x150", "--threads", t, "--tile", tile];
        assert!(
            image(&tag, &a) == base,
            "no depth, {t} threads, tiles {tile}"
        );
    }
    for bad in [
        &["--tile", "32x32", "--strip-rows", "8"][..],
        &["--tile", "0x32"],
    ] {
        let mut a = vec!["render"];
        a.extend_from_slice(bad);
        let o = run(&a);
        assert!(
            !o.status.success() && stderr(&o).contains("--tile"),
            "{bad:?}"
        );
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

// ---------------------------------------------------------------------------
// 1. No silent camera options.

#[test]
fn fov_and_eye_move_the_cubes_camera() {
    let plain = checksum(&[]);
    let fov = checksum(&["--fov", "10"]);
    let eye = checksum(&["--eye", "0.5,0.5,3", "--target", "0,0,0"]);
    let eye_only = checksum(&["--eye", "0.5,0.5,3"]);
    assert_ne!(plain, fov, "--fov 10 was ignored");
    assert_ne!(plain, eye, "--eye/--target were ignored");
    assert_ne!(eye, fov);
    assert_eq!(eye, eye_only, "the cubes' target is the origin");
    // The defaults are the scene's own camera, spelled out.
    let spelled = checksum(&["--eye", "0,3.75,6.5", "--target", "0,0,0", "--fov", "60"]);
    assert_eq!(plain, spelled);
}

#[test]
fn fov_alone_moves_the_sphere_and_bunny_cameras() {
    for scene in ["sphere", "bunny"] {
        let base = ["--scene", scene, "--size", "64x48"];
        let plain = checksum(&base);
        let mut narrow = base.to_vec();
        narrow.extend(["--fov", "10"]);
        assert_ne!(plain, checksum(&narrow), "{scene}: --fov ignored");
    }
}

#[test]
fn camera_options_without_a_camera_are_refused() {
    for opt in [
        &["--fov", "10"][..],
        &["--eye", "0.5,0.5,3", "--target", "0,0,0"],
        &["--target", "0,0,0"],
    ] {
        let mut a = vec!["render", "--scene", "quad", "--out"];
        let out = tmp("quad.png");
        a.push(out.to_str().unwrap());
        a.extend_from_slice(opt);
        let e = fails(&a);
        assert!(e.contains("quad") && e.contains("no camera"), "{e}");
        assert!(!out.exists());
    }
    let tris = tmp("one.txt");
    std::fs::write(&tris, "0 0 0 1  1 0 0 1  0 1 0 1\n").unwrap();
    let e = fails(&[
        "render",
        "--clip-tris",
        tris.to_str().unwrap(),
        "--fov",
        "30",
    ]);
    assert!(e.contains("--clip-tris") && e.contains("no camera"), "{e}");
}

// ---------------------------------------------------------------------------
// 2. No unexplained black images.

#[test]
fn straight_down_view_renders_the_teapot() {
    for eye in ["0,10,0", "0,-10,0"] {
        let (v, err) = stats(&[
            "--obj", TEAPOT, "--eye", eye, "--target", "0,0,0", "--cull", "none",
        ]);
        let px = v["counters"]["pixels_written"].as_u64().unwrap();
        assert!(px > 10_000, "eye {eye}: {px} pixels\n{err}");
        assert!(!err.contains("warning"), "{err}");
    }
}

#[test]
fn eye_equal_to_target_is_an_error() {
    let e = fails(&[
        "render",
        "--eye",
        "1,2,3",
        "--target",
        "1,2,3",
        "--out",
        "never.png",
    ]);
    assert!(e.contains("distinct"), "{e}");
    let e = fails(&[
        "render", "--obj", TEAPOT, "--eye", "0,0,0", "--target", "0,0,0",
    ]);
    assert!(e.contains("distinct"), "{e}");
    let e = fails(&["render", "--scene", "sphere", "--eye", "0,0,-3.2"]);
    assert!(e.contains("distinct"), "{e}");
    assert!(!Path::new("never.png").exists());
}

#[test]
fn render_with_no_pixel_says_so() {
    // Looking away from the cubes.
    let (v, err) = stats(&["--eye", "0,0,20", "--target", "0,0,40"]);
    assert_eq!(v["counters"]["pixels_written"], 0);
    assert!(err.contains("warning: the image is empty"), "{err}");
    assert!(
        err.contains("48 submitted") && err.contains("outside the view"),
        "{err}"
    );
    // A normal render has no warning.
    let (_, err) = stats(&[]);
    assert!(!err.contains("warning"), "{err}");
}

#[test]
fn obj_with_nan_coordinates_reports_the_dropped_triangles() {
    let obj = tmp("nan.obj");
    std::fs::write(
        &obj,
        "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nv nan 0 0\nf 1 2 3\nf 1 2 4\n",
    )
    .unwrap();
    let (v, err) = stats(&["--obj", obj.to_str().unwrap()]);
    assert_eq!(v["counters"]["rejected_nonfinite"], 1);
    assert!(err.contains("warning: 1 of 2 triangles dropped"), "{err}");
}

#[test]
fn obj_with_huge_coordinates_is_not_silent() {
    // 1e19 squared overflows f32: whatever the core makes of it (dropped,
    // or culled), the render must not pass for a normal one.
    let obj = tmp("huge.obj");
    std::fs::write(
        &obj,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1e19 0 0\nf 1 2 3\nf 1 2 4\n",
    )
    .unwrap();
    let (v, err) = stats(&["--obj", obj.to_str().unwrap(), "--cull", "none"]);
    let c = &v["counters"];
    let drew = c["pixels_written"].as_u64().unwrap() > 0;
    let dropped = c["rejected_nonfinite"].as_u64().unwrap() > 0;
    assert!(drew || err.contains("warning"), "{v}\n{err}");
    assert_eq!(dropped, err.contains("dropped"), "{v}\n{err}");
}

#[test]
fn nonfinite_clip_tris_are_reported() {
    let file = tmp("nan2.txt");
    std::fs::write(
        &file,
        "nan 0 0 1  1 0 0 1  0 1 0 1\n-1 -1 0 1  1 -1 0 1  0 1 0 1\n",
    )
    .unwrap();
    let (v, err) = stats(&["--clip-tris", file.to_str().unwrap()]);
    assert_eq!(v["counters"]["rejected_nonfinite"], 1);
    assert!(err.contains("1 of 2 triangles dropped"), "{err}");
}

#[test]
fn empty_clip_tris_file_is_an_error_like_an_empty_obj() {
    let tris = tmp("empty.txt");
    std::fs::write(&tris, "# nothing here\n\n").unwrap();
    let e = fails(&["render", "--clip-tris", tris.to_str().unwrap()]);
    assert!(e.contains("empty.txt") && e.contains("no triangles"), "{e}");
    let obj = tmp("empty.obj");
    std::fs::write(&obj, "").unwrap();
    let e = fails(&["render", "--obj", obj.to_str().unwrap()]);
    assert!(e.contains("empty.obj") && e.contains("no triangles"), "{e}");
}

// ---------------------------------------------------------------------------
// 3. Nothing is lost or half-written.

#[test]
fn two_outputs_naming_the_same_file_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().to_str().unwrap();
    let (a, b) = (format!("{d}/a.png"), format!("{d}/b.png"));
    let a_again = format!("{d}/./sub/../a.png");
    std::fs::create_dir(dir.path().join("sub")).unwrap();
    let e = fails(&["render", "--out", &b, "--depth-out", &b]);
    assert!(e.contains("same file"), "{e}");
    let e = fails(&["render", "--out", &a, "--id-out", &a_again]);
    assert!(e.contains("same file") && e.contains("--id-out"), "{e}");
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(left.len(), 1, "only sub/ may exist: {left:?}");
}

#[test]
fn depth_out_without_a_depth_buffer_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let raw = dir.path().join("x.raw");
    let out = dir.path().join("c.png");
    let e = fails(&[
        "render",
        "--depth",
        "none",
        "--depth-out",
        raw.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(e.contains("--depth-out") && e.contains("none"), "{e}");
    assert!(!raw.exists() && !out.exists());
}

#[test]
fn no_output_is_written_unless_all_can_be() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cubes.png");
    let e = fails(&[
        "render",
        "--out",
        out.to_str().unwrap(),
        "--depth-out",
        dir.path().join("missing/d.raw").to_str().unwrap(),
    ]);
    assert!(e.contains("missing"), "{e}");
    assert!(!out.exists(), "cubes.png was written before the failure");
    // A directory in the way of an output.
    std::fs::create_dir(dir.path().join("ids.png")).unwrap();
    fails(&[
        "render",
        "--out",
        out.to_str().unwrap(),
        "--id-out",
        dir.path().join("ids.png").to_str().unwrap(),
    ]);
    assert!(!out.exists());
    // And a successful render leaves no temporary file behind.
    ok(&[
        "render",
        "--size",
        "32x24",
        "--out",
        out.to_str().unwrap(),
        "--depth-out",
        dir.path().join("d.raw").to_str().unwrap(),
    ]);
    let mut names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["cubes.png", "d.raw", "ids.png"]);
}

// ---------------------------------------------------------------------------
// 4. Small things.

#[test]
fn stats_and_checksum_print_one_json_document() {
    let (v, err) = stats(&["--checksum", "--size", "64x48"]);
    let sum = checksum(&["--size", "64x48"]);
    assert_eq!(v["checksum"].as_str(), Some(sum.as_str()));
    assert!(
        v["counters"]["submitted"] == 48 && v["timings"].is_object(),
        "{v}"
    );
    // The "wrote" line stays, on stderr.
    assert!(
        err.contains("microraster: wrote ") && err.contains("64x48"),
        "{err}"
    );
}

#[test]
fn wrote_line_is_on_stderr() {
    let out = tmp("w.png");
    let o = ok(&["render", "--size", "16x16", "--out", out.to_str().unwrap()]);
    assert!(o.stdout.is_empty());
    assert!(stderr(&o).contains("wrote"), "{}", stderr(&o));
}

#[test]
fn negative_fov_gives_the_range_message() {
    for fov in ["-5", "0", "180", "nan"] {
        let o = run(&["render", "--fov", fov]);
        assert_eq!(o.status.code(), Some(2), "{fov}");
        let e = stderr(&o);
        assert!(e.contains("between 0 and 180"), "{fov}: {e}");
    }
    let o = run(&["bench", "--fov", "-5"]);
    assert!(stderr(&o).contains("between 0 and 180"), "{}", stderr(&o));
}

#[test]
fn obj_errors_name_the_file_and_line() {
    let obj = tmp("bad-face.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\n# faces\nf 1 2 x\n").unwrap();
    let e = fails(&["render", "--obj", obj.to_str().unwrap()]);
    assert!(
        e.contains("bad-face.obj: line 5:") && e.contains("`f 1 2 x`"),
        "{e}"
    );
    let obj = tmp("bad-vertex.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 O 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let e = fails(&["render", "--obj", obj.to_str().unwrap()]);
    assert!(
        e.contains("bad-vertex.obj: line 2:") && e.contains("three numbers"),
        "{e}"
    );
    let obj = tmp("bad-index.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n").unwrap();
    let e = fails(&["render", "--obj", obj.to_str().unwrap()]);
    assert!(e.contains("line 4:") && e.contains("index 7"), "{e}");
}

#[test]
fn the_fixture_obj_renders() {
    let (v, err) = stats(&["--obj", &data("two-triangles.obj"), "--size", "40x30"]);
    assert_eq!(v["counters"]["submitted"], 2);
    assert!(
        v["counters"]["pixels_written"].as_u64().unwrap() > 100,
        "{err}"
    );
}

#[test]
fn bench_without_a_tty_prints_progress_lines() {
    let o = bin()
        .args([
            "bench",
            "--scene",
            "cubes",
            "--size",
            "32x24",
            "--frames",
            "3",
            "--warmup",
            "1",
            "--no-split",
            "--compact",
        ])
        .env("MICRORASTER_PROGRESS_MS", "0")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    let lines: Vec<&str> = err.lines().filter(|l| l.contains("frame")).collect();
    assert!(lines.len() >= 3, "{err}");
    assert!(
        lines.iter().all(|l| l.starts_with("microraster bench: ")),
        "{err}"
    );
    assert!(
        !err.contains('\r'),
        "no terminal, no carriage returns: {err:?}"
    );
    let v: Value = serde_json::from_slice(&o.stdout).expect("stdout is only the JSON");
    assert!(v["median_ms"].as_f64().unwrap() > 0.0);
    // Short runs print nothing at the default interval.
    let o = run(&[
        "bench",
        "--scene",
        "cubes",
        "--size",
        "32x24",
        "--frames",
        "2",
        "--no-split",
    ]);
    assert!(o.status.success() && o.stderr.is_empty(), "{}", stderr(&o));
}

#[test]
fn render_help_says_which_options_each_scene_uses() {
    let o = ok(&["render", "--help"]);
    let h = String::from_utf8_lossy(&o.stdout);
    for want in [
        "Which options each source uses",
        "--scene cubes",
        "--scene sphere",
        "--scene quad          no camera",
        "--clip-tris FILE      no camera",
        "--obj FILE",
    ] {
        assert!(h.contains(want), "{want:?} missing from:\n{h}");
    }
}

// ---------------------------------------------------------------------------
// 6. Peers and report out of the default build.

#[test]
#[cfg(not(feature = "peers"))]
fn peers_without_the_feature_is_an_error_naming_it() {
    let e = fails(&[
        "bench", "--scene", "quad", "--size", "8x8", "--frames", "1", "--peers",
    ]);
    assert!(e.contains("--features peers"), "{e}");
    // bench itself works.
    ok(&[
        "bench", "--scene", "quad", "--size", "8x8", "--frames", "1", "--warmup", "0",
    ]);
}

#[test]
#[cfg(not(feature = "report"))]
fn report_without_the_feature_is_an_error_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r");
    let e = fails(&["report", "speed-vs-error", out.to_str().unwrap(), "--quick"]);
    assert!(e.contains("--features report"), "{e}");
    assert!(!out.exists());
}

/// `render --portals` on the house: the same image, the skipped rooms'
/// triangles counted as submitted and culled; refused without rooms.
#[test]
fn portals_draw_the_same_house_and_count_the_rooms() {
    let size = ["--scene", "house", "--size", "160x120", "--threads", "2"];
    let (all, _) = stats(&size);
    let mut with = size.to_vec();
    with.push("--portals");
    let (culled, _) = stats(&with);
    assert_eq!(all["checksum"], culled["checksum"]);
    let c = |v: &Value, k: &str| v["counters"][k].as_u64().unwrap();
    assert_eq!(c(&all, "submitted"), c(&culled, "submitted"));
    assert_eq!(c(&all, "culled_portal"), 0);
    assert!(c(&culled, "culled_portal") * 2 > c(&culled, "submitted"));
    assert!(c(&culled, "stored") < c(&all, "stored"));
    let out = tmp("portals-cubes.png");
    let e = fails(&["render", "--portals", "--out", out.to_str().unwrap()]);
    assert!(e.contains("--scene house"), "{e}");
    assert!(!out.exists());
    let ids = tmp("portals-ids.png");
    let e = fails(&[
        "render",
        "--scene",
        "house",
        "--portals",
        "--id-out",
        ids.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(e.contains("--id-out"), "{e}");
    assert!(!out.exists() && !ids.exists());
}

/// `render --cull-detail N` drops far objects whole (the herd from
/// afar), and `--cull-detail-boxes` draws them as boxes: the same
/// triangles dropped, box pieces counted, another image; the boxes
/// without `--cull-detail` are refused.
#[test]
fn cull_detail_drops_far_objects_and_boxes_draw_them() {
    let far = [
        "--scene", "spots", "--eye", "0,12,40", "--target", "0,0,0", "--size", "160x120",
    ];
    let c = |v: &Value, k: &str| v["counters"][k].as_u64().unwrap();
    let (exact, _) = stats(&far);
    let mut holes_args = far.to_vec();
    holes_args.extend(["--cull-detail", "7"]);
    let (holes, _) = stats(&holes_args);
    let mut boxes_args = holes_args.clone();
    boxes_args.push("--cull-detail-boxes");
    let (boxes, _) = stats(&boxes_args);
    assert_eq!(c(&exact, "culled_detail"), 0);
    assert!(c(&holes, "culled_detail") > 0, "{holes}");
    assert_eq!(c(&holes, "detail_boxes"), 0);
    assert_eq!(c(&boxes, "culled_detail"), c(&holes, "culled_detail"));
    assert!(c(&boxes, "detail_boxes") > 0, "{boxes}");
    assert_ne!(exact["checksum"], holes["checksum"]);
    assert_ne!(holes["checksum"], boxes["checksum"]);
    let out = tmp("boxes-alone.png");
    let o = run(&[
        "render",
        "--cull-detail-boxes",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("--cull-detail"), "{}", stderr(&o));
    assert!(!out.exists());
}

/// `bake-house` writes `house.rs` (the firmware's baked house, for any
/// size and camera) and nothing when it fails: too many rooms for the
/// firmware's bits, or a frame size the core refuses.
#[test]
fn bake_house_writes_the_house_or_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("baked");
    let o = ok(&[
        "bake-house",
        "--out",
        out.to_str().unwrap(),
        "--rooms",
        "2",
        "--camera",
        "5",
    ]);
    assert!(
        stdout(&o).contains("A house of 2x2 rooms"),
        "{}",
        stdout(&o)
    );
    let src = std::fs::read_to_string(out.join("house.rs")).unwrap();
    assert!(src.contains("--rooms 2 --camera 5"));
    assert!(src.contains("pub static PORTALS: [Portal; "));
    for bad in [
        &["--rooms", "9"][..],
        &["--rooms", "0"],
        &["--size", "0x240"],
    ] {
        let fresh = dir.path().join("none");
        let mut args = vec!["bake-house", "--out", fresh.to_str().unwrap()];
        args.extend_from_slice(bad);
        let o = run(&args);
        assert_ne!(o.status.code(), Some(0), "{bad:?}");
        assert!(!fresh.join("house.rs").exists(), "{bad:?}");
    }
}
