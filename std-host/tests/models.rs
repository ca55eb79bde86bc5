//! `render --obj` on the committed models, with no other flag: the Cornell
//! box shows its red and green walls, Spot its texture, the teapot and the
//! bunny smooth lighting; the default output is named after the model;
//! the shading options act (and are refused where they cannot); coverage
//! is the same in every shading mode.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const MODELS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../assets/models");

fn model(name: &str) -> String {
    format!("{MODELS}/{name}")
}

fn run_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_microraster"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("run microraster")
}

fn ok_in(dir: &Path, args: &[&str]) -> Output {
    let o = run_in(dir, args);
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

/// An RGB image read from a binary PPM.
struct Image {
    width: usize,
    rgb: Vec<[u8; 3]>,
}

fn read_ppm(path: &Path) -> Image {
    let bytes = std::fs::read(path).unwrap();
    // "P6\nW H\n255\n" then the pixels.
    let mut fields = Vec::new();
    let mut i = 0;
    while fields.len() < 4 {
        while bytes[i].is_ascii_whitespace() {
            i += 1;
        }
        let start = i;
        while !bytes[i].is_ascii_whitespace() {
            i += 1;
        }
        fields.push(String::from_utf8_lossy(&bytes[start..i]).into_owned());
    }
    let (w, h): (usize, usize) = (fields[1].parse().unwrap(), fields[2].parse().unwrap());
    let data = &bytes[i + 1..];
    assert_eq!(data.len(), w * h * 3);
    Image {
        width: w,
        rgb: data.chunks(3).map(|c| [c[0], c[1], c[2]]).collect(),
    }
}

fn render(dir: &Path, name: &str, extra: &[&str]) -> Image {
    let out = dir.join(format!(
        "{}-{}.ppm",
        name,
        extra.join("_").replace(['/', '.', ','], "-")
    ));
    let m = model(name);
    let mut args = vec!["render", "--obj", &m, "--size", "320x240", "--out"];
    let out_s = out.to_str().unwrap().to_string();
    args.push(&out_s);
    args.extend_from_slice(extra);
    ok_in(dir, &args);
    read_ppm(&out)
}

fn covered(img: &Image) -> Vec<[u8; 3]> {
    img.rgb
        .iter()
        .copied()
        .filter(|c| *c != [0, 0, 0])
        .collect()
}

#[test]
fn cornell_box_shows_red_and_green_walls() {
    let dir = tempfile::tempdir().unwrap();
    let img = render(dir.path(), "CornellBox-Original.obj", &[]);
    let px = covered(&img);
    let red = px
        .iter()
        .filter(|c| c[0] as u32 > 2 * c[1] as u32 + 10 && c[0] > c[2] * 2)
        .count();
    let green = px
        .iter()
        .filter(|c| c[1] as u32 > 2 * c[0] as u32 + 10 && c[1] > c[2] * 2)
        .count();
    assert!(red * 20 > px.len(), "red wall: {red} of {}", px.len());
    assert!(green * 20 > px.len(), "green wall: {green} of {}", px.len());
    // Red on the left, green on the right (seen from the open side).
    let mean_x = |pred: &dyn Fn(&[u8; 3]) -> bool| {
        let xs: Vec<usize> = (0..img.rgb.len())
            .filter(|&i| pred(&img.rgb[i]))
            .map(|i| i % img.width)
            .collect();
        xs.iter().sum::<usize>() as f64 / xs.len().max(1) as f64
    };
    let rx = mean_x(&|c| c[0] as u32 > 2 * c[1] as u32 + 10 && c[0] > c[2] * 2);
    let gx = mean_x(&|c| c[1] as u32 > 2 * c[0] as u32 + 10 && c[1] > c[2] * 2);
    assert!(rx < gx, "red at x {rx}, green at x {gx}");
}

#[test]
fn spot_shows_its_texture() {
    let dir = tempfile::tempdir().unwrap();
    let tex = render(dir.path(), "spot.obj", &[]);
    let plain = render(dir.path(), "spot.obj", &["--no-texture"]);
    let (a, b) = (covered(&tex), covered(&plain));
    assert!(a.len() > 5000, "{}", a.len());
    // The same pixels are covered; the texture's dark eyes and pink snout
    // change many of them.
    assert_eq!(
        tex.rgb.iter().filter(|c| **c != [0, 0, 0]).count(),
        plain.rgb.iter().filter(|c| **c != [0, 0, 0]).count()
    );
    let differ = tex
        .rgb
        .iter()
        .zip(&plain.rgb)
        .filter(|(x, y)| x.iter().zip(y.iter()).any(|(p, q)| p.abs_diff(*q) > 24))
        .count();
    assert!(differ * 10 > a.len(), "{differ} of {} differ", a.len());
    let pinkish = a
        .iter()
        .filter(|c| c[0] > 150 && c[0] as u32 > c[2] as u32 + 40)
        .count();
    let dark = a.iter().filter(|c| c.iter().all(|&v| v < 40)).count();
    assert!(pinkish > 100 && dark > 50, "pink {pinkish}, dark {dark}");
    // Untextured Spot is grey: no pink.
    assert!(b.iter().all(|c| c[0] as i32 - c[2] as i32 <= 8));
}

/// The mean absolute difference between horizontally adjacent covered
/// pixels (a measure of faceting).
fn roughness(img: &Image) -> f64 {
    let mut sum = 0u64;
    let mut n = 0u64;
    for (i, pair) in img.rgb.windows(2).enumerate() {
        if (i + 1) % img.width == 0 || pair[0] == [0, 0, 0] || pair[1] == [0, 0, 0] {
            continue;
        }
        sum += (0..3)
            .map(|k| pair[0][k].abs_diff(pair[1][k]) as u64)
            .sum::<u64>();
        n += 1;
    }
    sum as f64 / n.max(1) as f64
}

#[test]
fn teapot_and_bunny_are_smooth_and_every_mode_covers_the_same_pixels() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["teapot.obj", "stanford-bunny.obj"] {
        let mut ids = Vec::new();
        let mut rough = Vec::new();
        for mode in ["flat", "gouraud", "phong"] {
            let id_out = dir.path().join(format!("{name}-{mode}-ids.png"));
            let id_s = id_out.to_str().unwrap().to_string();
            let img = render(dir.path(), name, &["--shading", mode, "--id-out", &id_s]);
            ids.push(std::fs::read(&id_out).unwrap());
            rough.push(roughness(&img));
            // Lit: many levels of grey, not one.
            let mut levels: Vec<u8> = covered(&img).iter().map(|c| c[1]).collect();
            levels.sort_unstable();
            levels.dedup();
            assert!(levels.len() > 60, "{name} {mode}: {} levels", levels.len());
        }
        assert_eq!(ids[0], ids[1], "{name}: flat and gouraud ids");
        assert_eq!(ids[0], ids[2], "{name}: flat and phong ids");
        // Interpolated lighting is smoother than faceted.
        assert!(
            rough[1] < rough[0] && rough[2] < rough[0],
            "{name}: {rough:?}"
        );
    }
}

#[test]
fn default_output_is_named_after_the_model() {
    let dir = tempfile::tempdir().unwrap();
    let teapot = model("teapot.obj");
    let o = ok_in(dir.path(), &["render", "--obj", &teapot, "--size", "64x48"]);
    assert!(dir.path().join("teapot.png").is_file());
    assert!(!dir.path().join("cubes.png").exists());
    assert!(String::from_utf8_lossy(&o.stderr).contains("teapot.png"));
}

fn fails_in(dir: &Path, args: &[&str]) -> String {
    let o = run_in(dir, args);
    assert_eq!(o.status.code(), Some(1), "{args:?}");
    let e = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(e.starts_with("microraster: error: "), "{e}");
    e
}

#[test]
fn shading_options_are_refused_without_a_model_and_checked_with_one() {
    let dir = tempfile::tempdir().unwrap();
    for extra in [
        &["--shading", "flat"][..],
        &["--light", "1,0,0"],
        &["--no-texture"],
        &["--texture-filter", "nearest"],
    ] {
        let mut args = vec!["render", "--scene", "cubes"];
        args.extend_from_slice(extra);
        let e = fails_in(dir.path(), &args);
        assert!(e.contains("--obj"), "{e}");
    }
    let teapot = model("teapot.obj");
    let e = fails_in(
        dir.path(),
        &["render", "--obj", &teapot, "--light", "0,0,0"],
    );
    assert!(e.contains("--light"), "{e}");
    let missing: PathBuf = dir.path().join("none.png");
    let e = fails_in(
        dir.path(),
        &[
            "render",
            "--obj",
            &teapot,
            "--texture",
            missing.to_str().unwrap(),
        ],
    );
    assert!(e.contains("none.png"), "{e}");
    // Nothing was written by the failures.
    assert!(std::fs::read_dir(dir.path()).unwrap().next().is_none());
}

#[test]
fn the_light_direction_moves_the_lighting() {
    let dir = tempfile::tempdir().unwrap();
    let left = render(dir.path(), "teapot.obj", &["--light", "-1,0,0.2"]);
    let right = render(dir.path(), "teapot.obj", &["--light", "1,0,0.2"]);
    let brightness = |img: &Image, left_half: bool| {
        let mut s = 0u64;
        for (i, c) in img.rgb.iter().enumerate() {
            if (i % img.width < img.width / 2) == left_half {
                s += c[1] as u64;
            }
        }
        s
    };
    assert!(brightness(&left, true) > brightness(&left, false));
    assert!(brightness(&right, false) > brightness(&right, true));
}
