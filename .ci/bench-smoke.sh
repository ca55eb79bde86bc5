#!/usr/bin/env bash
# Smoke test of `microraster bench`: every built-in scene once at its real
# size with a few frames, the peers, thread lists and the memory floor.
# Checks that each run prints valid JSON with positive times and that
# output is identical across thread counts; it does not judge speed.
# Exits non-zero on the first failure. About a minute once the release
# binary is built (building it first takes a minute or two more).
# Set BENCH_SMOKE_CRITERION=1 to also compile the criterion benches.
set -euo pipefail
cd "$(dirname "$0")/.."

# The peers are a cargo feature of the host (not in the default build).
cargo build --release -q -p microraster-host --features peers
bin=target/release/microraster
out=target/ci/bench
mkdir -p "$out"

# check FILE EXPR...: each Python expression over the JSON object `d` must hold.
check() {
  local file=$1
  shift
  python3 - "$file" "$@" <<'PY'
import json, math, sys
path, *exprs = sys.argv[1:]
d = json.load(open(path))
def pos(x):
    return isinstance(x, (int, float)) and math.isfinite(x) and x > 0
for e in exprs:
    if not eval(e, {"d": d, "pos": pos}):
        sys.exit(f"{path}: check failed: {e}")
print(f"{path}: {d['scene']} {d['size']} threads {d['threads']}: "
      f"median {d['median_ms']:.3f} ms, min {d['min_ms']:.3f} ms")
PY
}

run() {
  local name=$1
  shift
  echo "+ microraster bench $*"
  "$bin" bench "$@" --compact >"$out/$name.json"
}

common='pos(d["median_ms"]) and pos(d["min_ms"]) and pos(d["triangles_per_s"])'

run cubes --scene cubes --frames 5 --warmup 1 --threads 1,2
check "$out/cubes.json" "$common" 'd["scaling"]["identical_output"] is True' \
  'pos(d["split"]["table"]["traversal_ms"])'

run sphere --scene sphere --frames 10 --warmup 2 --peers
check "$out/sphere.json" "$common" 'd["triangles"] == 20000' 'd["threads"] == 1' \
  'd["depth"] == "u16"' 'pos(d["peers"]["euc_over_microraster"])' \
  'pos(d["peers"]["embedded_graphics_2d"]["eg_over_microraster"])' \
  'd["peers"]["euc"]["covered_pixels"] == d["peers"]["microraster"]["covered_pixels"]'

run bunny --scene bunny --frames 3 --warmup 1 --threads 1,2 --peers
check "$out/bunny.json" "$common" 'd["triangles"] == 69451' \
  'd["scaling"]["identical_output"] is True' 'pos(d["peers"]["euc_over_microraster"])' \
  'pos(d["split"]["table"]["cull_clip_setup_ms"])'

run bunny-subdiv --scene bunny-subdiv --frames 1 --warmup 0 --no-split
check "$out/bunny-subdiv.json" "$common" 'd["triangles"] == 1111216'

run quad --scene quad --frames 5 --warmup 1
check "$out/quad.json" "$common" 'd["pixels_written"] == 1920 * 1080' \
  'pos(d["floor"]["floor_ms"])' 'pos(d["floor"]["frame_over_floor"])'

# Cluster culling's measurement (docs/culling.md), reduced: every method
# draws the frame per-triangle culling draws, and culls: the cluster
# methods more than a fifth, normal masks of 16 partitions something (the
# bunny's sub-pixel triangles pass its size guard in few classes), and
# the lecture's mask alone at least as much as the exact one in every
# sector table.
echo "+ microraster cull --cameras 8 --rounds 1"
"$bin" cull --cameras 8 --rounds 1 --json "$out/cull.json" >"$out/cull.md"
python3 - "$out/cull.json" <<'PY'
import json, sys
reports = json.load(open(sys.argv[1]))
assert len(reports) == 3, reports
for r in reports:
    for row in r["rows"]:
        assert row["frames_differing"] == 0, (r["model"], row)
    masks = [row for row in r["rows"] if isinstance(row["method"], dict)]
    named = {row["method"]: row for row in r["rows"] if not isinstance(row["method"], dict)}
    clusters = [named[m] for m in ("volumes", "volumes-tree", "cones", "cones-tree")]
    culled = [row["removed_before_transform"] for row in clusters]
    assert all(c > 0.2 for c in culled), (r["model"], culled)
    # The floors: the volumes' own cut submitted without a test keeps what
    # the tree draws; leaving out only the back faces keeps fewer, and only
    # what is set up fewer still, set up all the same.
    free, facing, floor = named["floor-volumes"], named["floor-facing"], named["floor"]
    tree = named["volumes-tree"]
    assert free["triangles_to_transform"] == tree["triangles_to_transform"], (free, tree)
    assert floor["triangles_to_transform"] <= facing["triangles_to_transform"] < tree["triangles_to_transform"], r["model"]
    assert len({row["triangles_set_up"] for row in named.values()}) == 1, r["model"]
    by_n = {row["method"]["mask"]: row["removed_before_transform"] for row in masks}
    assert sorted(by_n) == [4, 8, 16] and by_n[16] > 0, (r["model"], by_n)
    for m in r["masks"]:
        assert all(exact <= alone for _, exact, alone in m["sectors"]), (r["model"], m)
    print(f'{r["model"]}: removed before transform {", ".join(f"{c:.3f}" for c in culled)}; '
          f'normal masks {", ".join(f"N={n} {c:.3f}" for n, c in sorted(by_n.items()))}')
PY

# Detail culling (lossy): far away, it drops more than the exact tree and
# reports the pixels it changed.
echo "+ microraster cull --cameras 8 --rounds 1 --distance 10 --detail 2"
"$bin" cull --cameras 8 --rounds 1 --distance 10 --detail 2 --json "$out/cull-detail.json" >"$out/cull-detail.md"
python3 - "$out/cull-detail.json" <<'PY'
import json, sys
reports = json.load(open(sys.argv[1]))
for r in reports:
    rows = {row["method"]: row for row in r["rows"] if isinstance(row["method"], str)}
    tree, detail = rows["volumes-tree"], rows["detail"]
    assert tree["frames_differing"] == 0, (r["model"], tree)
    assert detail["removed_before_transform"] >= tree["removed_before_transform"], r["model"]
    assert (detail["frames_differing"] == 0) == (detail["pixels_differing"] == 0), detail
    print(f'{r["model"]}: detail 2 px removes {detail["removed_before_transform"]:.3f}, '
          f'{detail["pixels_differing"]:.1f} pixels a frame changed')
assert any(row["pixels_differing"] > 0 for r in reports for row in r["rows"] if row["method"] == "detail")
PY

# Occlusion culling (docs/culling.md), reduced: the herd's frames are the
# plain ones, and from eye height the hi-z hides most of what is in the
# frustum.
echo "+ microraster cull --occlusion --cameras 8 --rounds 1"
"$bin" cull --occlusion --cameras 8 --rounds 1 --json "$out/occlusion.json" >"$out/occlusion.md"
python3 - "$out/occlusion.json" <<'PY'
import json, sys
rows = json.load(open(sys.argv[1]))
assert [r["rows"] for r in rows] == [240, 16], rows
for r in rows:
    assert r["identical"], r
    assert r["stored"][1] < r["stored"][0], r
whole = rows[0]
hidden = whole["culled_occlusion"] / (whole["submitted"] - whole["culled_object"])
assert hidden > 0.5, whole
print(f'occlusion: {hidden:.3f} of the triangles in the frustum hidden, '
      f'set up {whole["stored"][0]:.0f} -> {whole["stored"][1]:.0f}')
PY

# Portal culling (docs/culling.md), all 64 cameras (under a second): the
# frames are the plain ones and at least 80 % of the rooms are skipped.
echo "+ microraster cull --portals --rounds 1"
"$bin" cull --portals --rounds 1 --json "$out/portals.json" >"$out/portals.md"
python3 - "$out/portals.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
assert r["identical"], r
skipped = 1 - r["reached"] / r["cells"]
assert skipped >= 0.8, r
assert r["stored"][1] < r["stored"][0], r
print(f'portals: {skipped:.3f} of the rooms skipped, '
      f'set up {r["stored"][0]:.0f} -> {r["stored"][1]:.0f}')
PY

if [ "${BENCH_SMOKE_CRITERION:-0}" = 1 ]; then
  cargo bench -q -p microraster-host --features criterion --bench core --no-run
fi

echo "bench smoke: all runs passed"
