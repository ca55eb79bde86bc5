//! The report's instruction-count axis: the firmware's configuration
//! table of record in `docs/embedded.md`, read at compile time.
//!
//! Design note: `.ci/firmware.sh` runs the firmware (the four cubes,
//! 320x240 `Rgb565`, set up once) under QEMU with `-icount shift=0` in
//! each configuration and holds its counts to the table under
//! "Configurations (the report's speed axis)"; the report reads that
//! same table (`include_str!`), so it shows the counts of record and
//! never runs QEMU itself. Counts are deterministic; what blurs them is
//! the SysTick measurement (one tick is 40 instructions on the MPS2
//! boards, 62.5 on the micro:bit, and the strip clears are one strip's
//! count times the strips), a few thousand instructions at most: the
//! report calls a lead real only when it is over [`COUNT_NOISE`].

use super::Configuration;

/// `docs/embedded.md`, as compiled in.
pub const EMBEDDED_MD: &str = include_str!("../../../docs/embedded.md");

/// The heading of the configuration table in `docs/embedded.md`.
pub const TABLE_HEADING: &str = "### Configurations (the report's speed axis)";

/// Relative noise of an instruction count: 1 %, well over the SysTick
/// granularity (40 instructions a tick on the M4F, 62.5 on the micro:bit,
/// the clears' tick times the strips: at most a few thousand of the
/// render's 0.8 M and 3.3 M).
pub const COUNT_NOISE: f64 = 0.01;

/// The M4F's QEMU machine.
pub const M4F: &str = "mps2-an386";
/// The M0's QEMU machine.
pub const M0: &str = "microbit";

/// One row of the table: a board and configuration, its counts.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FirmwareRow {
    /// QEMU machine (`mps2-an386`, `microbit`).
    pub board: String,
    /// Configuration label, e.g. `S8 u16 libm` or `S8 u16 libm no-i32-edges`.
    pub config: String,
    /// Instructions per frame, display push included.
    pub frame: u64,
    /// Render: the frame less the display push.
    pub render: u64,
    /// Rasterization: the render less clears and geometry.
    pub raster: u64,
    /// RAM, bytes (statics and stack).
    pub ram: u64,
}

/// A count as `1,234,567`, `1234567` or `**1234567**`.
fn count(cell: &str) -> Option<u64> {
    let digits: String = cell
        .chars()
        .filter(|c| !matches!(c, ',' | '*' | ' ' | '_'))
        .collect();
    digits.parse().ok()
}

/// The rows of the table under [`TABLE_HEADING`] in `md`: the first
/// table after the heading (before the next heading), its columns found
/// by name in its header row. Rows that do not parse are errors.
pub fn parse_table(md: &str) -> Result<Vec<FirmwareRow>, String> {
    let start = md
        .find(TABLE_HEADING)
        .ok_or_else(|| format!("no {TABLE_HEADING:?} in docs/embedded.md"))?;
    let mut lines = md[start + TABLE_HEADING.len()..].lines();
    let cells = |l: &str| -> Vec<String> {
        l.trim()
            .trim_matches('|')
            .split('|')
            .map(|c| c.trim().to_string())
            .collect()
    };
    let header = loop {
        match lines.next() {
            Some(l) if l.starts_with('#') => return Err("no table under the heading".into()),
            Some(l) if l.trim_start().starts_with('|') => break cells(l),
            Some(_) => continue,
            None => return Err("no table under the heading".into()),
        }
    };
    let col = |name: &str| {
        header
            .iter()
            .position(|h| h.to_lowercase().starts_with(name))
            .ok_or_else(|| format!("no {name:?} column in the configuration table"))
    };
    let (b, c, f, r, x, m) = (
        col("board")?,
        col("configuration")?,
        col("frame")?,
        col("render")?,
        col("rasterization")?,
        col("ram")?,
    );
    let mut out = Vec::new();
    for l in lines {
        let l = l.trim();
        if !l.starts_with('|') {
            break;
        }
        let row = cells(l);
        if row
            .iter()
            .all(|c| c.chars().all(|c| matches!(c, '-' | ':')))
        {
            continue; // the alignment row
        }
        let get = |i: usize, what: &str| {
            row.get(i)
                .and_then(|s| count(s))
                .ok_or_else(|| format!("configuration table: bad {what} in {l:?}"))
        };
        out.push(FirmwareRow {
            board: row.get(b).cloned().unwrap_or_default(),
            config: row.get(c).cloned().unwrap_or_default(),
            frame: get(f, "frame")?,
            render: get(r, "render")?,
            raster: get(x, "rasterization")?,
            ram: get(m, "RAM")?,
        });
    }
    if out.is_empty() {
        return Err("the configuration table has no rows".into());
    }
    Ok(out)
}

/// The table of record (compiled in).
pub fn table() -> Result<Vec<FirmwareRow>, String> {
    parse_table(EMBEDDED_MD)
}

/// The row for `board` and the report's configuration `c`, if measured.
pub fn lookup<'a>(
    rows: &'a [FirmwareRow],
    board: &str,
    c: &Configuration,
) -> Option<&'a FirmwareRow> {
    let label = c.label();
    rows.iter().find(|r| r.board == board && r.config == label)
}

/// A configuration's counts on the two boards.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DeviceCounts {
    /// M4F render instructions.
    pub m4f_render: Option<u64>,
    /// M4F rasterization instructions.
    pub m4f_raster: Option<u64>,
    /// M0 render instructions.
    pub m0_render: Option<u64>,
    /// M0 rasterization instructions.
    pub m0_raster: Option<u64>,
}

/// `c`'s counts from `rows`.
pub fn counts(rows: &[FirmwareRow], c: &Configuration) -> DeviceCounts {
    let m4f = lookup(rows, M4F, c);
    let m0 = lookup(rows, M0, c);
    DeviceCounts {
        m4f_render: m4f.map(|r| r.render),
        m4f_raster: m4f.map(|r| r.raster),
        m0_render: m0.map(|r| r.render),
        m0_raster: m0.map(|r| r.raster),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::{Variant, CONFIGURATIONS};

    #[test]
    fn the_real_table_has_every_configuration_on_both_boards() {
        let rows = table().unwrap();
        for c in CONFIGURATIONS {
            let n = counts(&rows, &c);
            // The firmware draws the grid, immediate mode, and with u16
            // depth the clipless mode, 1/w depth and 32x32 tiles; not
            // u32 or f32 1/w, u32 clipless or other tile sizes.
            let u16 = c.depth_bits == 16 && !c.float_depth;
            let recorded = matches!(c.variant, Variant::Base | Variant::Immediate)
                || (matches!(
                    c.variant,
                    Variant::Clipless | Variant::InvW | Variant::Tiles(32)
                ) && u16);
            if !recorded {
                assert!(
                    n.m4f_render.is_none() && n.m0_render.is_none(),
                    "{}",
                    c.label()
                );
                continue;
            }
            for (what, v) in [
                ("M4F render", n.m4f_render),
                ("M4F raster", n.m4f_raster),
                ("M0 render", n.m0_render),
                ("M0 raster", n.m0_raster),
            ] {
                let v = v.unwrap_or_else(|| panic!("{} {what}: no row", c.label()));
                // Immediate mode on the M0 reports all of it as geometry.
                if what == "M0 raster" && c.variant != Variant::Base {
                    continue;
                }
                assert!(v > 100_000, "{} {what} {v}", c.label());
            }
            let (r, x) = (n.m4f_render.unwrap(), n.m4f_raster.unwrap());
            assert!(x < r, "{}: rasterization {x} over render {r}", c.label());
        }
        // The fast-path row is there too, and the fast path saves.
        let fast = rows
            .iter()
            .find(|r| r.board == M4F && r.config == "S8 u16 libm")
            .unwrap();
        let slow = rows
            .iter()
            .find(|r| r.board == M4F && r.config == "S8 u16 libm no-i32-edges")
            .unwrap();
        assert!(slow.raster > fast.raster);
        // RAM within the budgets.
        for r in &rows {
            let budget = if r.board == M0 { 16384 } else { 24576 };
            assert!(r.ram <= budget, "{r:?}");
        }
    }

    #[test]
    fn parses_commas_bold_and_column_order() {
        let md = "intro\n### Configurations (the report's speed axis)\n\ntext\n\n\
                  | configuration | board | RAM B | frame | render | rasterization |\n\
                  |---|---|--:|--:|--:|--:|\n\
                  | S8 u16 libm | microbit | 13,352 | **3,924,687** | 3345687 | 2780187 |\n\
                  \nafter | not a row |\n";
        let rows = parse_table(md).unwrap();
        assert_eq!(
            rows,
            vec![FirmwareRow {
                board: "microbit".into(),
                config: "S8 u16 libm".into(),
                frame: 3_924_687,
                render: 3_345_687,
                raster: 2_780_187,
                ram: 13_352,
            }]
        );
        assert!(parse_table("no heading").is_err());
        let bad = md.replace("3345687", "lots");
        assert!(parse_table(&bad).is_err());
        let none = "### Configurations (the report's speed axis)\n\n## Next\n| a |\n";
        assert!(parse_table(none).is_err());
    }
}
