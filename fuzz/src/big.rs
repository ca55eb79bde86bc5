//! The "real mesh" part of a fuzz input: a compact, self-describing byte
//! layout that can hold thousands of triangles (a few bytes each), so that
//! libFuzzer can grow inputs into real meshes and the seed corpus can hold
//! pieces of the shared models (`fuzz/seeds.py` writes it).
//!
//! Input layout (all little-endian):
//!
//! ```text
//! u32 n                  length of the mesh blob (clamped to what is there; 0: none)
//! [u8; n] blob           the mesh, below
//! ...                    the rest: `FrameInput` through `arbitrary`
//! ```
//!
//! Blob layout (every field optional: a short blob just ends early):
//!
//! ```text
//! u16 width, u16 height  frame size override (0: keep FrameInput's)
//! u8 flags               bit 0-1: backend (0 default, 1 micromath, 2 libm)
//!                        bit 2: bounding sphere; bit 3-4: colour mode
//!                        bit 5-6: path (0 submit_mesh, 1 cached,
//!                        2 processed, 3 processed with a short cache)
//!                        bit 7: storage exactly `Frame::storage_for(n)`
//!                        (else 7 pieces a triangle)
//! u8 first_id
//! f32 x 10               eye xyz, target xyz, fov, near, far, angle_y
//! u16 vertices           then that many i16 triples (position = v / 8192)
//! u16 triples            the triangles, to the end (indices may be out of range)
//! ```

/// Largest number of triangles taken from a blob.
pub const MAX_BIG_TRIANGLES: usize = 6000;

/// A mesh read from the blob.
#[derive(Clone, Debug, Default)]
pub struct BigMesh {
    /// Frame size override (both nonzero) .
    pub size: Option<(u32, u32)>,
    /// See the layout.
    pub flags: u8,
    /// First triangle id (times 256).
    pub first_id: u8,
    /// Camera numbers.
    pub camera: [f32; 10],
    /// Positions.
    pub positions: Vec<[f32; 3]>,
    /// Triangles.
    pub indices: Vec<[u32; 3]>,
}

struct Reader<'a>(&'a [u8]);

impl Reader<'_> {
    fn take<const N: usize>(&mut self) -> Option<[u8; N]> {
        let (a, b) = self.0.split_first_chunk::<N>()?;
        self.0 = b;
        Some(*a)
    }
}

impl BigMesh {
    /// Parses a blob (never fails: missing fields are zero / empty).
    pub fn parse(blob: &[u8]) -> BigMesh {
        let mut r = Reader(blob);
        let mut m = BigMesh::default();
        let w = r.take::<2>().map_or(0, u16::from_le_bytes) as u32;
        let h = r.take::<2>().map_or(0, u16::from_le_bytes) as u32;
        if w != 0 && h != 0 {
            m.size = Some((w, h));
        }
        m.flags = r.take::<1>().map_or(0, |b| b[0]);
        m.first_id = r.take::<1>().map_or(0, |b| b[0]);
        for c in m.camera.iter_mut() {
            *c = r.take::<4>().map_or(0.0, f32::from_le_bytes);
        }
        let nv = r.take::<2>().map_or(0, u16::from_le_bytes) as usize;
        for _ in 0..nv {
            let Some(b) = r.take::<6>() else { break };
            let c = |k: usize| i16::from_le_bytes([b[2 * k], b[2 * k + 1]]) as f32 / 8192.0;
            m.positions.push([c(0), c(1), c(2)]);
        }
        while m.indices.len() < MAX_BIG_TRIANGLES {
            let Some(b) = r.take::<6>() else { break };
            let c = |k: usize| u16::from_le_bytes([b[2 * k], b[2 * k + 1]]) as u32;
            m.indices.push([c(0), c(1), c(2)]);
        }
        m
    }

    /// The backend choice (0 default, 1 micromath, 2 libm).
    pub fn backend(&self) -> u8 {
        self.flags & 3
    }
    /// Whether the mesh gets its bounding sphere.
    pub fn bounds(&self) -> bool {
        self.flags & 4 != 0
    }
    /// Colour mode (0 uniform, 1 per triangle, 2 per vertex).
    pub fn color_mode(&self) -> u8 {
        (self.flags >> 3) & 3
    }
    /// Submission path.
    pub fn path(&self) -> u8 {
        (self.flags >> 5) & 3
    }
    /// Storage of exactly `Frame::storage_for(n)`.
    pub fn tight_storage(&self) -> bool {
        self.flags & 0x80 != 0
    }
}

/// Splits a whole fuzz input into the mesh blob and the rest.
pub fn split_input(data: &[u8]) -> (&[u8], &[u8]) {
    let Some((n, rest)) = data.split_first_chunk::<4>() else {
        return (&[], data);
    };
    let n = (u32::from_le_bytes(*n) as usize).min(rest.len());
    rest.split_at(n)
}
