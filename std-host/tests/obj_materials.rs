//! `obj::load_obj_shaded`: normals, UVs, materials and textures, on small
//! files written here and on the committed models; bad input is an error
//! naming the file or a counted repair, never a panic.

use microraster_host::obj::{
    load_obj, load_obj_shaded, load_png_rgb, ShadedMesh, DEFAULT_DIFFUSE, MAX_TEXTURE_SIDE,
};
use std::path::{Path, PathBuf};
use tempfile::TempDir;

fn models() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/models")
}

fn write(dir: &TempDir, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.path().join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

/// An RGB8 PNG of `w x h` where pixel (x, y) is (x, y, 7).
fn png_bytes(w: u32, h: u32) -> Vec<u8> {
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, w, h);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let mut wr = enc.write_header().unwrap();
    let data: Vec<u8> = (0..h)
        .flat_map(|y| (0..w).flat_map(move |x| [x as u8, y as u8, 7]))
        .collect();
    wr.write_image_data(&data).unwrap();
    wr.finish().unwrap();
    out
}

fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= b as u32;
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

/// A PNG claiming `w x h` with no pixel data (the `png` encoder refuses to
/// write a zero-size image).
fn png_header_only(w: u32, h: u32) -> Vec<u8> {
    let mut out = vec![0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a];
    let mut chunk = b"IHDR".to_vec();
    chunk.extend(w.to_be_bytes());
    chunk.extend(h.to_be_bytes());
    chunk.extend([8, 2, 0, 0, 0]);
    out.extend(13u32.to_be_bytes());
    out.extend(&chunk);
    out.extend(crc32(&chunk).to_be_bytes());
    // Empty IDAT and IEND chunks, so the header is read and checked.
    for name in [b"IDAT", b"IEND"] {
        out.extend(0u32.to_be_bytes());
        out.extend(name);
        out.extend(crc32(name).to_be_bytes());
    }
    out
}

const QUAD_UV: &str = "mtllib m.mtl\n\
    v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
    vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
    usemtl tex\nf 1/1 2/2 3/3 4/4\n";

fn textured_dir(mtl: &str, png: Option<&[u8]>) -> (TempDir, PathBuf) {
    let dir = TempDir::new().unwrap();
    let obj = write(&dir, "quad.obj", QUAD_UV.as_bytes());
    write(&dir, "m.mtl", mtl.as_bytes());
    if let Some(p) = png {
        write(&dir, "t.png", p);
    }
    (dir, obj)
}

fn is_unit(n: [f32; 3]) -> bool {
    ((n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt() - 1.0).abs() < 1e-5
}

#[test]
fn textured_quad_loads_material_texture_and_uvs() {
    let mtl = "newmtl tex\nKd 0.5 0.25 1.5\nKs 0.1 0.2 0.3\nNs 32\nmap_Kd t.png\n";
    let (_dir, obj) = textured_dir(mtl, Some(&png_bytes(3, 2)));
    let m = load_obj_shaded(&obj, None).unwrap();
    assert_eq!(m.indices.len(), 2);
    assert_eq!(m.materials.len(), 1, "no default material needed");
    let mat = &m.materials[0];
    assert_eq!(mat.name, "tex");
    assert_eq!(mat.diffuse, [0.5, 0.25, 1.0], "Kd clamped to 0..=1");
    assert_eq!(mat.specular, [0.1, 0.2, 0.3]);
    assert_eq!(mat.shininess, 32.0);
    let tex = mat.texture.as_ref().unwrap();
    assert_eq!((tex.width, tex.height), (3, 2));
    // Row 0 is the top of the file.
    assert_eq!(tex.rgb[0], [0, 0, 7]);
    assert_eq!(tex.rgb[5], [2, 1, 7]);
    assert_eq!(m.triangle_material, vec![0, 0]);
    let uvs = m.uvs.as_ref().unwrap();
    assert_eq!(uvs.len(), m.positions.len());
    for (p, uv) in m.positions.iter().zip(uvs) {
        assert_eq!([p[0], p[1]], *uv, "this quad's UVs equal its x, y");
    }
    assert_eq!(m.normals.len(), m.positions.len());
    for n in &m.normals {
        assert!((n[2] - 1.0).abs() < 1e-6, "{n:?}");
    }
    assert!(!m.normals_from_file);
    assert_eq!(m.counts, Default::default());
    assert!(m.warnings.is_empty());
}

#[test]
fn file_normals_are_normalised_and_nan_ones_replaced_and_counted() {
    let dir = TempDir::new().unwrap();
    let obj = write(
        &dir,
        "n.obj",
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 2\nvn nan 0 0\nf 1//1 2//1 3//2\n",
    );
    let m = load_obj_shaded(&obj, None).unwrap();
    assert_eq!(m.positions.len(), 3);
    assert!(m.normals.iter().all(|&n| is_unit(n)));
    assert!(m.normals.iter().all(|n| (n[2] - 1.0).abs() < 1e-6));
    assert_eq!(m.counts.bad_file_normals, 1);
    assert!(
        m.warnings.iter().any(|w| w.contains("n.obj")),
        "{:?}",
        m.warnings
    );
    assert!(m.uvs.is_none());
}

#[test]
fn degenerate_faces_get_a_counted_fallback_normal() {
    let dir = TempDir::new().unwrap();
    // All three corners on one line: zero area, no normal.
    let obj = write(&dir, "d.obj", b"v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
    let m = load_obj_shaded(&obj, None).unwrap();
    assert_eq!(m.counts.normal_fallbacks, 3);
    assert!(m.normals.iter().all(|&n| n == [0.0, 0.0, 1.0]));
    assert!(m.warnings.iter().any(|w| w.contains("d.obj")));
}

#[test]
fn no_mtl_gives_the_default_material() {
    let dir = TempDir::new().unwrap();
    let obj = write(&dir, "p.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    let m = load_obj_shaded(&obj, None).unwrap();
    assert_eq!(m.materials.len(), 1);
    assert_eq!(m.materials[0].diffuse, DEFAULT_DIFFUSE);
    assert_eq!(m.triangle_material, vec![0]);
    assert_eq!(m.counts.default_material_triangles, 1);
    assert_eq!(m.counts.missing_mtl_files, 0);
}

#[test]
fn missing_mtl_file_is_a_counted_warning() {
    let dir = TempDir::new().unwrap();
    let obj = write(
        &dir,
        "p.obj",
        b"mtllib gone.mtl\nusemtl red\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    );
    let m = load_obj_shaded(&obj, None).unwrap();
    assert_eq!(m.counts.missing_mtl_files, 1);
    assert_eq!(
        m.materials[m.triangle_material[0] as usize].diffuse,
        DEFAULT_DIFFUSE
    );
    let w = m.warnings.join("\n");
    assert!(w.contains("p.obj") && w.contains("gone.mtl"), "{w}");
}

#[test]
fn malformed_mtl_is_an_error_with_its_line() {
    let (_dir, obj) = textured_dir("newmtl tex\n\nKd 0.5 red 1\n", None);
    let e = load_obj_shaded(&obj, None).unwrap_err();
    assert!(e.contains("m.mtl") && e.contains("line 3"), "{e}");
}

#[test]
fn missing_texture_is_an_error_naming_it() {
    let (_dir, obj) = textured_dir("newmtl tex\nmap_Kd t.png\n", None);
    let e = load_obj_shaded(&obj, None).unwrap_err();
    assert!(
        e.contains("t.png") && e.contains("quad.obj") && e.contains("tex"),
        "{e}"
    );
}

#[test]
fn non_png_texture_is_an_error() {
    let (_dir, obj) = textured_dir("newmtl tex\nmap_Kd t.png\n", Some(b"P6\n1 1\n255\nabc"));
    let e = load_obj_shaded(&obj, None).unwrap_err();
    assert!(e.contains("t.png") && e.contains("PNG"), "{e}");
}

#[test]
fn truncated_png_texture_is_an_error() {
    let mut bytes = png_bytes(16, 16);
    bytes.truncate(bytes.len() - 30);
    let (_dir, obj) = textured_dir("newmtl tex\nmap_Kd t.png\n", Some(&bytes));
    let e = load_obj_shaded(&obj, None).unwrap_err();
    assert!(e.contains("t.png"), "{e}");
}

#[test]
fn zero_size_texture_is_an_error() {
    for (w, h) in [(0, 4), (4, 0)] {
        let (_dir, obj) = textured_dir("newmtl tex\nmap_Kd t.png\n", Some(&png_header_only(w, h)));
        let e = load_obj_shaded(&obj, None).unwrap_err();
        // The decoder itself refuses it ("Invalid image dimensions").
        assert!(e.contains("t.png") && e.contains("dimensions"), "{e}");
    }
}

#[test]
fn oversized_texture_is_an_error_before_decoding() {
    // Only the header: the size is refused before any pixel is read.
    let big = png_header_only(MAX_TEXTURE_SIDE + 1, 1);
    let (dir, obj) = textured_dir("newmtl tex\nmap_Kd t.png\n", Some(&big));
    let e = load_obj_shaded(&obj, None).unwrap_err();
    assert!(e.contains("t.png") && e.contains("4096"), "{e}");
    let e = load_png_rgb(&dir.path().join("t.png")).unwrap_err();
    assert!(e.contains("at most"), "{e}");
}

#[test]
fn uv_and_normal_indices_out_of_range_are_errors_with_the_line() {
    let head = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n";
    let cases = [
        ("f 1/1 2/2 3/1\n", "texture coordinate index 2"),
        ("f 1/0 2/1 3/1\n", "start at 1"),
        ("f 1/-2 2/1 3/1\n", "reaches back"),
        ("f 1/x 2/1 3/1\n", "not a texture coordinate index"),
        ("f 1//1 2//1 3//9\n", "normal index 9"),
        ("f 1//-3 2//1 3//1\n", "reaches back"),
    ];
    for (face, want) in cases {
        let dir = TempDir::new().unwrap();
        let obj = write(&dir, "bad.obj", format!("{head}{face}").as_bytes());
        let e = load_obj_shaded(&obj, None).unwrap_err();
        assert!(
            e.contains("bad.obj") && e.contains("line 6") && e.contains(want),
            "{face}: {e}"
        );
    }
}

#[test]
fn faces_mixing_uv_and_no_uv_are_counted() {
    let dir = TempDir::new().unwrap();
    let obj = write(
        &dir,
        "mix.obj",
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0.5 0.5\n\
          o a\nf 1/1 2/1 3/1\no b\nf 2 4 3\n",
    );
    let m = load_obj_shaded(&obj, None).unwrap();
    let uvs = m.uvs.as_ref().unwrap();
    assert_eq!(uvs.len(), m.positions.len());
    assert_eq!(m.counts.missing_uvs, 3);
    assert!(m.warnings.iter().any(|w| w.contains("mix.obj")));
}

#[test]
fn nan_uvs_are_replaced_and_counted() {
    let dir = TempDir::new().unwrap();
    let obj = write(
        &dir,
        "u.obj",
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt nan 0\nvt 1 0\nf 1/1 2/2 3/2\n",
    );
    let m = load_obj_shaded(&obj, None).unwrap();
    assert_eq!(m.counts.bad_uvs, 1);
    assert!(m
        .uvs
        .unwrap()
        .iter()
        .all(|t| t.iter().all(|c| c.is_finite())));
}

#[test]
fn bad_position_index_keeps_its_line() {
    let dir = TempDir::new().unwrap();
    let obj = write(
        &dir,
        "p.obj",
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 7/1\n",
    );
    let e = load_obj_shaded(&obj, None).unwrap_err();
    assert!(e.contains("p.obj") && e.contains("line 5"), "{e}");
    let e = load_obj_shaded(&dir.path().join("none.obj"), None).unwrap_err();
    assert!(e.contains("none.obj"), "{e}");
}

#[test]
fn cornell_box_has_red_and_green_walls() {
    let m = load_obj_shaded(&models().join("CornellBox-Original.obj"), None).unwrap();
    assert_eq!(m.indices.len(), 36);
    assert_eq!(m.triangle_material.len(), 36);
    assert_eq!(m.counts.missing_mtl_files, 0);
    assert_eq!(m.counts.default_material_triangles, 0);
    let by_name = |n: &str| m.materials.iter().position(|x| x.name == n).unwrap();
    let (left, right) = (by_name("leftWall"), by_name("rightWall"));
    assert_eq!(m.materials[left].diffuse, [0.63, 0.065, 0.05]);
    assert_eq!(m.materials[right].diffuse, [0.14, 0.45, 0.091]);
    assert_eq!(m.materials[left].shininess, 10.0);
    let uses = |i: usize| {
        m.triangle_material
            .iter()
            .filter(|&&t| t as usize == i)
            .count()
    };
    assert_eq!((uses(left), uses(right)), (2, 2));
    assert!(m.normals.iter().all(|&n| is_unit(n)));
    // Same positions as the plain loader.
    let plain = load_obj(&models().join("CornellBox-Original.obj")).unwrap();
    assert_eq!(m.to_loaded(), plain);
}

#[test]
fn spot_has_uvs_everywhere_and_its_texture() {
    let tex = models().join("spot_texture.png");
    let m = load_obj_shaded(&models().join("spot.obj"), Some(&tex)).unwrap();
    assert_eq!(m.indices.len(), 5856);
    let uvs = m.uvs.as_ref().unwrap();
    assert_eq!(uvs.len(), m.positions.len());
    assert!(m.positions.len() >= 2930);
    assert_eq!(m.counts.missing_uvs, 0);
    assert_eq!(m.materials.len(), 1);
    let t = m.materials[0].texture.as_ref().unwrap();
    assert_eq!((t.width, t.height, t.rgb.len()), (1024, 1024, 1024 * 1024));
    check_smooth(&m, "spot");
    // UV seams do not crease: duplicated positions share one normal.
    let mut seen = std::collections::HashMap::new();
    for (p, n) in m.positions.iter().zip(&m.normals) {
        let key = p.map(f32::to_bits);
        assert_eq!(*seen.entry(key).or_insert(*n), *n);
    }
    assert!(seen.len() < m.positions.len(), "Spot has seams");
}

fn check_smooth(m: &ShadedMesh, what: &str) {
    assert_eq!(m.normals.len(), m.positions.len());
    assert!(m.normals.iter().all(|&n| is_unit(n)), "{what}");
    let n = m.positions.len() as f64;
    let centroid: [f64; 3] =
        [0, 1, 2].map(|k| m.positions.iter().map(|p| p[k] as f64).sum::<f64>() / n);
    let outward = m
        .positions
        .iter()
        .zip(&m.normals)
        .filter(|(p, nrm)| {
            (0..3)
                .map(|k| (p[k] as f64 - centroid[k]) * nrm[k] as f64)
                .sum::<f64>()
                > 0.0
        })
        .count();
    assert!(
        outward as f64 > 0.75 * n,
        "{what}: {outward} of {n} point outward"
    );
}

#[test]
fn teapot_and_bunny_get_outward_smooth_normals() {
    for name in ["teapot.obj", "stanford-bunny.obj"] {
        let m = load_obj_shaded(&models().join(name), None).unwrap();
        assert!(!m.normals_from_file);
        assert!(m.uvs.is_none());
        check_smooth(&m, name);
    }
}

#[test]
fn plain_loader_refuses_bad_uv_indices_without_panicking() {
    let dir = TempDir::new().unwrap();
    let obj = write(
        &dir,
        "p.obj",
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/-5 2/1 3/1\n",
    );
    let e = load_obj(&obj).unwrap_err();
    assert!(e.contains("p.obj") && e.contains("line 5"), "{e}");
}

#[test]
fn smooth_normals_keep_hard_edges_and_smooth_seams() {
    // Cornell box: flat walls (every wall's normal is one axis), not rounded corners.
    let m = load_obj_shaded(&models().join("CornellBox-Original.obj"), None).unwrap();
    let floor = m.materials.iter().position(|x| x.name == "floor").unwrap() as u32;
    for (t, tri) in m.indices.iter().enumerate() {
        if m.triangle_material[t] == floor {
            for &i in tri {
                let n = m.normals[i as usize];
                assert!(n[1].abs() > 0.999, "floor normal {n:?}");
            }
        }
    }
    // Two triangles folded by 20 degrees, sharing an edge by value only
    // (as at a UV seam): the shared corners get one smooth normal.
    let dir = TempDir::new().unwrap();
    let z = 20f32.to_radians().sin();
    let text =
        format!("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 0 0\nv 0 1 0\nv 1 1 {z}\nf 1 2 3\nf 4 6 5\n");
    let obj = write(&dir, "fold.obj", text.as_bytes());
    let m = load_obj_shaded(&obj, None).unwrap();
    let at = |p: [f32; 2]| {
        m.positions
            .iter()
            .enumerate()
            .filter(move |(_, q)| q[0] == p[0] && q[1] == p[1])
            .map(|(i, _)| m.normals[i])
            .collect::<Vec<_>>()
    };
    let shared = at([1.0, 0.0]);
    assert_eq!(shared.len(), 2);
    assert_eq!(shared[0], shared[1]);
    let own = at([0.0, 0.0])[0];
    assert!(
        own[2] > shared[0][2] && shared[0][2] < 1.0,
        "{own:?} {shared:?}"
    );
}

#[test]
fn texture_options_and_subfolders_are_followed() {
    let dir = TempDir::new().unwrap();
    std::fs::create_dir(dir.path().join("mats")).unwrap();
    let obj = write(
        &dir,
        "quad.obj",
        QUAD_UV.replace("m.mtl", "mats/m.mtl").as_bytes(),
    );
    // Two materials on one file: beside the MTL, with map_Kd options.
    write(
        &dir,
        "mats/m.mtl",
        b"newmtl tex\nmap_Kd -s 1 1 1 t.png\nnewmtl other\nmap_Kd t.png\n",
    );
    write(&dir, "mats/t.png", &png_bytes(2, 2));
    let m = load_obj_shaded(&obj, None).unwrap();
    assert_eq!(m.materials.len(), 2);
    assert!(m
        .materials
        .iter()
        .all(|x| x.texture.as_ref().is_some_and(|t| t.width == 2)));
    // Beside the OBJ when not beside the MTL.
    std::fs::rename(dir.path().join("mats/t.png"), dir.path().join("t.png")).unwrap();
    assert!(load_obj_shaded(&obj, None).is_ok());
}

#[test]
fn unknown_material_names_get_the_default_with_a_warning() {
    let (dir, _) = textured_dir("newmtl tex\nKd 1 0 0\n", None);
    let obj = write(
        &dir,
        "two.obj",
        b"mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl tex\nf 1 2 3\nusemtl nope\nf 1 3 2\n",
    );
    let m = load_obj_shaded(&obj, None).unwrap();
    assert_eq!(m.materials.len(), 2);
    assert_eq!(
        m.materials[m.triangle_material[0] as usize].diffuse,
        [1.0, 0.0, 0.0]
    );
    assert_eq!(
        m.materials[m.triangle_material[1] as usize].diffuse,
        DEFAULT_DIFFUSE
    );
    assert_eq!(m.counts.default_material_triangles, 1);
    assert!(m
        .warnings
        .iter()
        .any(|w| w.contains("two.obj") && w.contains("default")));
}
