//! `microraster bake`: the generated Rust source for the committed Spot and
//! Cornell box, i16 quantization error, decimation, bad options, and a failed
//! bake leaving nothing behind.

use microraster_host::bake::{
    self, bake, bake_source, decimate, quantize_i16, resample_box, rgb565, BakeOptions,
};
use microraster_host::cli::PositionsArg;
use microraster_host::obj::{load_obj_shaded, TextureImage};
use std::path::{Path, PathBuf};
use std::process::Command;

fn models() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/models")
}

fn spot_opts() -> BakeOptions {
    BakeOptions {
        model: models().join("spot.obj"),
        texture: Some(models().join("spot_texture.png")),
        texture_size: 64,
        positions: PositionsArg::F32,
        max_triangles: None,
    }
}

/// The number of entries of the array `name` (lines between its `= [` and
/// the closing `];`, or comma-separated items on them).
fn entries(src: &str, name: &str) -> usize {
    let start = src
        .find(&format!("pub static {name}:"))
        .unwrap_or_else(|| panic!("no {name}"));
    let body = &src[start..];
    let open = body.find("= [").unwrap() + 3;
    let close = open + body[open..].find("];").unwrap();
    let inner = &body[open..close];
    // Items are `[..]`, `Vec3::new(..)` or plain numbers; count top-level commas.
    let mut depth = 0i32;
    let mut items = 0;
    let mut any = false;
    for c in inner.chars() {
        match c {
            '[' | '(' => depth += 1,
            ']' | ')' => depth -= 1,
            ',' if depth == 0 => items += 1,
            c if !c.is_whitespace() => any = true,
            _ => {}
        }
    }
    if any && !inner.trim_end().ends_with(',') {
        items += 1;
    }
    items
}

fn konst(src: &str, name: &str) -> usize {
    let start = src.find(&format!("pub const {name}: ")).unwrap();
    let line = src[start..].lines().next().unwrap();
    line.split('=')
        .nth(1)
        .unwrap()
        .trim()
        .trim_end_matches(';')
        .parse()
        .unwrap()
}

#[test]
fn spot_bakes_with_every_array_sized() {
    let dir = tempfile::tempdir().unwrap();
    let (report, path) = bake(&spot_opts(), dir.path()).unwrap();
    assert_eq!(path, dir.path().join("spot.rs"));
    let src = std::fs::read_to_string(&path).unwrap();
    let (n, m) = (konst(&src, "VERTEX_COUNT"), konst(&src, "TRIANGLE_COUNT"));
    assert_eq!((n, m), (report.vertices, report.triangles));
    assert_eq!(m, 5856);
    assert_eq!(
        src.matches("Vec3::new(").count(),
        2 * n,
        "positions + normals"
    );
    assert_eq!(entries(&src, "POSITIONS"), n);
    assert_eq!(entries(&src, "NORMALS"), n);
    assert_eq!(entries(&src, "UVS"), n);
    assert_eq!(entries(&src, "INDICES"), m);
    assert_eq!(entries(&src, "TRIANGLE_MATERIAL"), m);
    assert_eq!(
        entries(&src, "MATERIAL_DIFFUSE"),
        konst(&src, "MATERIAL_COUNT")
    );
    assert_eq!(konst(&src, "TEXTURE_WIDTH"), 64);
    assert_eq!(konst(&src, "TEXTURE_HEIGHT"), 64);
    assert!(src.contains("pub static TEXTURE: [u16; 4096] = ["));
    assert_eq!(entries(&src, "TEXTURE"), 64 * 64);
    assert!(src.contains("pub static MATERIAL_TEXTURED: [bool; MATERIAL_COUNT] = [true];"));
    assert!(!src.contains("POSITIONS_I16"));
    assert!(!src.contains("NaN") && !src.contains("inf"));
    // Positions round-trip exactly.
    let mesh = load_obj_shaded(&models().join("spot.obj"), None).unwrap();
    let first = &mesh.positions[0];
    assert!(src.contains(&format!(
        "Vec3::new({:?}, {:?}, {:?})",
        first[0], first[1], first[2]
    )));
    // UVs are flipped into the core's row-0-first convention.
    let uv = mesh.uvs.as_ref().unwrap()[0];
    assert!(
        src.contains(&format!("    [{:?}, {:?}],\n", uv[0], 1.0 - uv[1])),
        "uv {uv:?}"
    );
    assert_eq!(report.texture_bytes, 8192);
    assert!(report.total_bytes > report.f32_position_bytes + report.texture_bytes);
    // Only the one file: no temporary left over.
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, vec![std::ffi::OsString::from("spot.rs")]);
}

#[test]
fn cornell_box_bakes_material_colours() {
    let dir = tempfile::tempdir().unwrap();
    let opts = BakeOptions {
        model: models().join("CornellBox-Original.obj"),
        texture: None,
        positions: PositionsArg::I16,
        ..spot_opts()
    };
    let (report, path) = bake(&opts, dir.path()).unwrap();
    assert_eq!(path.file_name().unwrap(), "cornellbox_original.rs");
    let src = std::fs::read_to_string(&path).unwrap();
    assert_eq!(report.triangles, 36);
    assert!(!src.contains("TEXTURE") && !src.contains("UVS"));
    assert_eq!(entries(&src, "MATERIAL_DIFFUSE"), 8);
    // leftWall (Kd 0.63 0.065 0.05) is red: round(x * 255).
    assert!(src.contains("[161, 17, 13]"), "{src}");
    assert!(src.contains("[36, 115, 23]"), "green rightWall");
    assert_eq!(entries(&src, "POSITIONS_I16"), 72);
    assert!(src.contains("pub const POSITION_SCALE: [f32; 3] = ["));
    assert!(src.contains("pub const POSITION_OFFSET: [f32; 3] = ["));
    assert_eq!(src.matches("Vec3::new(").count(), 72, "normals only");
}

#[test]
fn i16_error_is_within_half_a_step_per_axis() {
    let mesh = load_obj_shaded(&models().join("spot.obj"), None).unwrap();
    let q = quantize_i16(&mesh.positions);
    for (i, p) in mesh.positions.iter().enumerate() {
        let d = q.dequantize(i);
        for k in 0..3 {
            let err = (d[k] as f64 - p[k] as f64).abs();
            // Half a step, plus the f32 rounding of q * scale + offset.
            let bound = 0.5 * q.scale[k] as f64 + 2.0 * f32::EPSILON as f64 * 1.1;
            assert!(err <= bound, "vertex {i} axis {k}: {err} > {bound}");
        }
    }
    assert!(q.q.iter().flatten().all(|&c| c != i16::MIN));
    let (max, rms) = bake::quantization_error(&mesh.positions, &q);
    assert!(rms <= max && max > 0.0);
    // Half a step on every axis, relative to the diagonal: below 1 / 65534.
    assert!(max < 1.0 / 65534.0, "{max}");
    // A flat axis quantizes to zero without dividing by zero.
    let flat = quantize_i16(&[[1.0, 2.0, 3.0], [2.0, 2.0, 3.0]]);
    assert_eq!(flat.dequantize(1), [2.0, 2.0, 3.0]);
}

#[test]
fn decimation_reaches_the_budget_and_keeps_a_mesh() {
    let mesh = load_obj_shaded(
        &models().join("spot.obj"),
        Some(&models().join("spot_texture.png")),
    )
    .unwrap();
    for max in [2000usize, 500, 100] {
        let d = decimate(&mesh, max).unwrap();
        assert!(
            !d.indices.is_empty() && d.indices.len() <= max,
            "{max}: {}",
            d.indices.len()
        );
        assert!(d.indices.len() > max / 4, "{max}: only {}", d.indices.len());
        let n = d.positions.len();
        assert_eq!(d.normals.len(), n);
        assert_eq!(d.uvs.as_ref().unwrap().len(), n);
        assert_eq!(d.triangle_material.len(), d.indices.len());
        for t in &d.indices {
            assert!(t.iter().all(|&i| (i as usize) < n));
            assert!(t[0] != t[1] && t[1] != t[2] && t[0] != t[2], "degenerate");
        }
        // Deterministic.
        assert_eq!(decimate(&mesh, max).unwrap(), d);
    }
    // Under the budget already: unchanged.
    assert_eq!(decimate(&mesh, 10_000).unwrap(), mesh);
    // A budget no grid can meet is an error, not an empty mesh.
    assert!(decimate(&mesh, 1).is_err());
    // Through the bake: the file says so.
    let dir = tempfile::tempdir().unwrap();
    let opts = BakeOptions {
        max_triangles: Some(300),
        positions: PositionsArg::I16,
        ..spot_opts()
    };
    let (r, path) = bake(&opts, dir.path()).unwrap();
    assert!(r.triangles <= 300 && r.triangles > 0 && r.source_triangles == 5856);
    let src = std::fs::read_to_string(path).unwrap();
    assert_eq!(entries(&src, "INDICES"), r.triangles);
    assert_eq!(entries(&src, "POSITIONS_I16"), r.vertices);
}

#[test]
fn bad_texture_sizes_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    for size in [0, 3, 48, 2048] {
        let opts = BakeOptions {
            texture_size: size,
            ..spot_opts()
        };
        let e = bake(&opts, dir.path()).unwrap_err();
        assert!(
            e.contains("power of two") && e.contains("1024"),
            "{size}: {e}"
        );
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    // The command line refuses them the same way (clap's status 2).
    for size in ["0", "3", "2048", "x"] {
        let o = Command::new(env!("CARGO_BIN_EXE_microraster"))
            .args([
                "bake",
                "--out",
                dir.path().to_str().unwrap(),
                "--texture-size",
                size,
            ])
            .arg(models().join("spot.obj"))
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{size}");
        assert!(String::from_utf8_lossy(&o.stderr).contains("power of two"));
    }
}

#[test]
fn failed_bakes_leave_nothing_in_the_folder() {
    let dir = tempfile::tempdir().unwrap();
    // A texture that is not there.
    let opts = BakeOptions {
        texture: Some(dir.path().join("none.png")),
        ..spot_opts()
    };
    let e = bake(&opts, dir.path()).unwrap_err();
    assert!(e.contains("none.png"), "{e}");
    // A NaN position: no literal for it.
    let obj = dir.path().join("nan.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n").unwrap();
    let e = bake(
        &BakeOptions {
            model: obj.clone(),
            texture: None,
            ..spot_opts()
        },
        dir.path(),
    )
    .unwrap_err();
    assert!(e.contains("nan.obj") && e.contains("NaN"), "{e}");
    std::fs::remove_file(&obj).unwrap();
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    // The target cannot be written (a folder is in the way): no temporary left.
    std::fs::create_dir(dir.path().join("spot.rs")).unwrap();
    assert!(bake(&spot_opts(), dir.path()).is_err());
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, vec![std::ffi::OsString::from("spot.rs")]);
    // An earlier good bake survives a failed one untouched.
    let good = tempfile::tempdir().unwrap();
    let (_, path) = bake(&spot_opts(), good.path()).unwrap();
    let before = std::fs::read(&path).unwrap();
    assert!(bake(
        &BakeOptions {
            max_triangles: Some(1),
            ..spot_opts()
        },
        good.path()
    )
    .is_err());
    assert_eq!(std::fs::read(&path).unwrap(), before);
    assert_eq!(std::fs::read_dir(good.path()).unwrap().count(), 1);
}

#[test]
fn texture_resampling_and_rgb565() {
    assert_eq!(rgb565([255, 255, 255]), 0xffff);
    assert_eq!(rgb565([0, 0, 0]), 0);
    assert_eq!(rgb565([255, 0, 0]), 0xf800);
    assert_eq!(rgb565([0, 255, 0]), 0x07e0);
    assert_eq!(rgb565([0, 0, 255]), 0x001f);
    // 128 rounds to 16 of 31 (15.56) and 32 of 63 (31.6).
    assert_eq!(rgb565([128, 128, 128]), (16 << 11) | (32 << 5) | 16);
    // 4x2: left half black, right half white, top row red channel 10.
    let rgb = vec![
        [10, 0, 0],
        [10, 0, 0],
        [255, 255, 255],
        [255, 255, 255],
        [0, 0, 0],
        [0, 0, 0],
        [255, 255, 255],
        [255, 255, 255],
    ];
    let tex = TextureImage {
        width: 4,
        height: 2,
        rgb,
    };
    assert_eq!(resample_box(&tex, 2, 1), vec![[5, 0, 0], [255, 255, 255]]);
    assert_eq!(
        resample_box(&tex, 1, 2),
        vec![[133, 128, 128], [128, 128, 128]]
    );
    // Upsampling repeats texels; same size is the identity.
    assert_eq!(resample_box(&tex, 8, 4)[0], [10, 0, 0]);
    assert_eq!(resample_box(&tex, 4, 2), tex.rgb);
    // 3 -> 2 splits the middle texel between both.
    let row = TextureImage {
        width: 3,
        height: 1,
        rgb: vec![[0; 3], [90; 3], [180; 3]],
    };
    assert_eq!(resample_box(&row, 2, 1), vec![[30; 3], [150; 3]]);
}

#[test]
fn generated_source_is_the_same_twice_and_names_are_identifiers() {
    let mesh = load_obj_shaded(&models().join("CornellBox-Original.obj"), None).unwrap();
    let opts = BakeOptions {
        model: models().join("CornellBox-Original.obj"),
        texture: None,
        ..spot_opts()
    };
    let a = bake_source(&mesh, "c", "c", &opts).unwrap();
    let b = bake_source(&mesh, "c", "c", &opts).unwrap();
    assert_eq!(a, b);
    assert_eq!(
        bake::module_name(Path::new("x/CornellBox-Original.obj")),
        "cornellbox_original"
    );
    assert_eq!(bake::module_name(Path::new("3d model.obj")), "m3d_model");
}

#[test]
fn bake_help_and_summary() {
    let o = Command::new(env!("CARGO_BIN_EXE_microraster"))
        .args(["bake", "--help"])
        .output()
        .unwrap();
    let help = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success());
    for word in [
        "--texture-size",
        "--positions",
        "--max-triangles",
        "--texture",
        "POSITIONS_I16",
        "Rgb565",
    ] {
        assert!(help.contains(word), "{word}: {help}");
    }
    let dir = tempfile::tempdir().unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_microraster"))
        .arg("bake")
        .arg(models().join("spot.obj"))
        .args(["--positions", "i16", "--texture"])
        .arg(models().join("spot_texture.png"))
        .arg("--out")
        .arg(dir.path())
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for word in [
        "positions f32: 38700 bytes",
        "positions i16: 19374 bytes",
        "max ",
        "RMS ",
        "total baked",
    ] {
        assert!(out.contains(word), "{word}: {out}");
    }
    assert!(dir.path().join("spot.rs").is_file());
}

/// Compiles `baked` with rustc (as a library, warnings denied) next to a
/// stand-in `microraster::Vec3` with the core's `const fn new`. Returns
/// false, with a note, where no rustc can be run.
fn compiles(baked: &Path) -> bool {
    let dir = tempfile::tempdir().unwrap();
    let lib = dir.path().join("check.rs");
    std::fs::write(
        &lib,
        format!(
            "pub mod microraster {{\n\
             pub struct Vec3 {{ pub x: f32, pub y: f32, pub z: f32 }}\n\
             impl Vec3 {{ pub const fn new(x: f32, y: f32, z: f32) -> Self {{ Vec3 {{ x, y, z }} }} }}\n\
             }}\n\
             pub mod baked {{ use crate::microraster; include!({:?}); }}\n",
            baked.display().to_string()
        ),
    )
    .unwrap();
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let out = Command::new(rustc)
        .args([
            "--edition",
            "2021",
            "--crate-type",
            "lib",
            "-D",
            "warnings",
            "--out-dir",
        ])
        .arg(dir.path())
        .arg(&lib)
        .output();
    match out {
        Err(e) => {
            eprintln!("note: no rustc to run ({e}): the baked source was not compiled");
            false
        }
        Ok(o) => {
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
            true
        }
    }
}

#[test]
fn baked_source_compiles() {
    let dir = tempfile::tempdir().unwrap();
    let cornell = BakeOptions {
        model: models().join("CornellBox-Original.obj"),
        texture: None,
        ..spot_opts()
    };
    let (_, path) = bake(&cornell, dir.path()).unwrap();
    compiles(&path);
    let small_spot = BakeOptions {
        max_triangles: Some(200),
        positions: PositionsArg::I16,
        texture_size: 8,
        ..spot_opts()
    };
    let (_, path) = bake(&small_spot, dir.path()).unwrap();
    compiles(&path);
}

#[test]
fn bake_errors_are_one_line_with_status_1() {
    let dir = tempfile::tempdir().unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_microraster"))
        .args(["bake", "missing.obj", "--out"])
        .arg(dir.path())
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.starts_with("microraster: error: ") && e.contains("missing.obj"),
        "{e}"
    );
    assert_eq!(e.trim().lines().count(), 1, "{e}");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

/// The `[a, b, c],` rows of the `[[u32; 3]; _]` array `name` in `src`.
fn triangles_of(src: &str, name: &str) -> Vec<[u32; 3]> {
    let start = src
        .find(&format!("pub static {name}:"))
        .unwrap_or_else(|| panic!("no {name}"));
    let body = &src[start..];
    let close = body.find("\n];").unwrap();
    body[..close]
        .lines()
        .skip(1)
        .map(|l| {
            let v: Vec<u32> = l
                .trim()
                .trim_start_matches('[')
                .trim_end_matches("],")
                .split(", ")
                .map(|x| x.parse().unwrap())
                .collect();
            [v[0], v[1], v[2]]
        })
        .collect()
}

/// A triangle rotated so its smallest index is first (winding kept).
fn canonical(t: [u32; 3]) -> [u32; 3] {
    let k = (0..3).min_by_key(|&k| t[k]).unwrap();
    [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
}

#[test]
fn the_cluster_bake_reorders_the_models_own_triangles_and_fits_its_counts() {
    let mesh = load_obj_shaded(&models().join("spot.obj"), None).unwrap();
    let opts = BakeOptions {
        max_triangles: Some(600),
        ..spot_opts()
    };
    let (model, report) = bake_source(&mesh, "spot", "spot", &opts).unwrap();
    let (src, c) = bake::cluster_source(&mesh, "spot", &opts).unwrap();
    assert_eq!(bake::cluster_source(&mesh, "spot", &opts).unwrap().0, src);
    // The same triangles, winding kept, over the model file's vertices.
    let mut baked: Vec<_> = triangles_of(&model, "INDICES")
        .into_iter()
        .map(canonical)
        .collect();
    let mut clustered: Vec<_> = triangles_of(&src, "CLUSTER_INDICES")
        .into_iter()
        .map(canonical)
        .collect();
    assert_eq!(clustered.len(), report.triangles);
    baked.sort_unstable();
    clustered.sort_unstable();
    assert_eq!(
        baked, clustered,
        "the cluster order is a permutation of INDICES"
    );
    assert!(c.clusters > 1 && c.nodes >= c.clusters && c.inner_nodes == c.nodes - c.clusters);
    assert_eq!(src.matches("microraster::Cluster {").count(), c.clusters);
    assert_eq!(entries(&src, "CLUSTER_VERTICES"), c.list_entries);
    assert!(src.contains(&format!("pub const CLUSTER_COUNT: usize = {};", c.clusters)));
    assert!(src.contains(&format!(
        "pub const CLUSTER_NODE_COUNT: usize = {};",
        c.nodes
    )));
    assert_eq!(src.matches("microraster::ClusterNode {").count(), c.nodes);
    // Every vertex list entry names one of the model's vertices.
    assert!(src
        .split("pub static CLUSTER_VERTICES")
        .nth(1)
        .unwrap()
        .split(|ch: char| !ch.is_ascii_digit())
        .filter_map(|x| x.parse::<usize>().ok())
        .skip(2) // `u32` and the array length
        .all(|v| v < report.vertices));
}

#[test]
fn float_literals_read_back_bit_for_bit() {
    let mut x = 0x0001_2345u32;
    let mut values = vec![
        0.0,
        -0.0,
        1.0,
        -1.5,
        f32::MIN_POSITIVE,
        f32::MAX,
        f32::MIN,
        1e-45,
        0.1,
    ];
    for _ in 0..10_000 {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        let v = f32::from_bits(x);
        if v.is_finite() {
            values.push(v);
        }
    }
    for v in values {
        let lit = bake::f32_literal(v);
        assert_eq!(lit.parse::<f32>().unwrap().to_bits(), v.to_bits(), "{lit}");
    }
    assert_eq!(bake::f32_literal(f32::INFINITY), "f32::INFINITY");
    assert_eq!(bake::f32_literal(f32::NEG_INFINITY), "f32::NEG_INFINITY");
    assert_eq!(bake::f32_literal(f32::NAN), "f32::NAN");
}

#[test]
fn bake_clusters_writes_both_files_or_neither() {
    let dir = tempfile::tempdir().unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_microraster"))
        .arg("bake")
        .arg(models().join("spot.obj"))
        .args(["--max-triangles", "400", "--clusters", "--out"])
        .arg(dir.path())
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.contains("clusters: "), "{out}");
    assert!(dir.path().join("spot.rs").is_file());
    assert!(dir.path().join("spot_clusters.rs").is_file());
    // A bake that fails writes nothing: not the model, not the clusters.
    let empty = tempfile::tempdir().unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_microraster"))
        .arg("bake")
        .arg(models().join("spot.obj"))
        .args(["--max-triangles", "1", "--clusters", "--out"])
        .arg(empty.path())
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(std::fs::read_dir(empty.path()).unwrap().count(), 0);
}

/// `bake --normal-masks N`: the classes file holds `normal_mask::build`'s
/// classes for the model file's triangles in their order, its sizes and
/// spheres (bit for bit), and is written with the model or not at all.
#[test]
fn the_classes_bake_is_normal_mask_build_of_the_models_triangles() {
    let mesh = load_obj_shaded(&models().join("spot.obj"), None).unwrap();
    let opts = BakeOptions {
        max_triangles: Some(600),
        ..spot_opts()
    };
    let (model, _) = bake_source(&mesh, "spot", "spot", &opts).unwrap();
    let decimated = decimate(&mesh, 600).unwrap();
    let src = bake::classes_source(&decimated, "spot", &opts, 4).unwrap();
    let positions: Vec<microraster::Vec3> = decimated
        .positions
        .iter()
        .map(|p| microraster::Vec3::new(p[0], p[1], p[2]))
        .collect();
    assert_eq!(triangles_of(&model, "INDICES"), decimated.indices);
    let want = microraster_host::normal_mask::build(&positions, &decimated.indices, 4).unwrap();
    let body = |name: &str| -> Vec<String> {
        let start = src.find(&format!("pub static {name}:")).unwrap();
        let b = &src[start..];
        let open = b.find("= [").unwrap() + 3;
        let close = open + b[open..].find("\n];").unwrap();
        b[open..close]
            .split(|c: char| c == ',' || c.is_whitespace() || c == '[' || c == ']')
            .filter(|x| !x.is_empty())
            .map(str::to_string)
            .collect()
    };
    let classes: Vec<u16> = body("CLASSES").iter().map(|x| x.parse().unwrap()).collect();
    assert_eq!(classes, want.classes);
    let sizes: Vec<f32> = body("CLASS_SIZES")
        .iter()
        .map(|x| x.parse().unwrap())
        .collect();
    let want_sizes: Vec<f32> = want.sizes.iter().flatten().copied().collect();
    assert_eq!(
        sizes.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
        want_sizes.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
    );
    assert_eq!(
        src.matches("microraster::BoundingSphere {").count(),
        6 * 4 * 4
    );
    assert!(src.contains("pub const PARTITIONS: u8 = 4;"));
    assert!(src.contains("pub const CLASS_COUNT: usize = 96;"));
    // Partitions beyond 16 are refused, and nothing is written.
    let empty = tempfile::tempdir().unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_microraster"))
        .arg("bake")
        .arg(models().join("spot.obj"))
        .args(["--max-triangles", "400", "--normal-masks", "17", "--out"])
        .arg(empty.path())
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("partitions"));
    assert_eq!(std::fs::read_dir(empty.path()).unwrap().count(), 0);
    let dir = tempfile::tempdir().unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_microraster"))
        .arg("bake")
        .arg(models().join("spot.obj"))
        .args(["--max-triangles", "400", "--normal-masks", "8", "--out"])
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(dir.path().join("spot.rs").is_file());
    assert!(dir.path().join("spot_classes.rs").is_file());
}
