#!/usr/bin/env bash
# The firmware example (examples/firmware) under QEMU on three cores, and
# the core built for RISC-V.
#
# For each board: build the firmware, run it (each run wrapped in
# `timeout`), require exit code 0 (the firmware exits 0 only if its frame's
# checksum equals the one its build.rs computed on the host) and require
# the checksum it prints to equal examples/firmware/host-checksums.txt
# (which std-host/tests/firmware_frame.rs checks on the host). Then the
# build variants (no depth buffer, flat colour) and the table of flash,
# RAM and instructions, printed as markdown for docs/embedded.md. Then the
# same for baked, textured, lit Spot in its six shading variants (after
# checking that the committed bakes are what `microraster bake` writes,
# and that the unlit and untextured variants link no lighting or texture
# code), with its own table, and Spot in cluster order on the M4F with
# the cluster tests of docs/culling.md (the same frame, fewer
# instructions), and a herd of Spots with and without occlusion culling
# on the M4F. Then the configuration sweep of the cubes on
# the M4F and the M0 (subpixel bits, depth buffer, float backend, the i32
# edge fast path: the speed axis of `microraster report speed-vs-error`),
# with its own table of record.
#
# The builds and QEMU runs go first, FIRMWARE_JOBS at once (default: one
# a core, at most 4), each worker in a target dir of its own; the checks
# then read their outputs in order. FIRMWARE_JOBS=1 runs them one by one.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD

step() { printf '\n== %s\n' "$*"; }

step "tools: qemu-system-arm, arm-none-eabi-size, rust targets"
if ! command -v qemu-system-arm >/dev/null || ! command -v arm-none-eabi-size >/dev/null; then
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq qemu-system-arm binutils-arm-none-eabi >/dev/null
fi
rustup target add thumbv6m-none-eabi thumbv7m-none-eabi thumbv7em-none-eabihf riscv32imc-unknown-none-elf
qemu-system-arm --version | head -1

step "core for riscv32imc-unknown-none-elf (no_std, both float backends)"
cargo build -p microraster --release --target riscv32imc-unknown-none-elf
cargo build -p microraster --release --target riscv32imc-unknown-none-elf --no-default-features --features micromath

step "baked Spot is what microraster bake writes today (examples/firmware/baked)"
# The commands of record (docs/embedded.md): re-bake into a temp dir and
# require the committed files to be the same, so they cannot go stale.
cargo build -q --release -p microraster-host
bake=$(mktemp -d)
target/release/microraster bake --out "$bake/full" --texture assets/models/spot_texture.png \
  --texture-size 256 --clusters --normal-masks 16 assets/models/spot.obj >/dev/null
target/release/microraster bake --out "$bake/small" --texture assets/models/spot_texture.png \
  --texture-size 128 --max-triangles 1500 assets/models/spot.obj >/dev/null
diff -q "$bake/full/spot.rs" examples/firmware/baked/spot.rs
diff -q "$bake/full/spot_clusters.rs" examples/firmware/baked/spot_clusters.rs
diff -q "$bake/full/spot_classes.rs" examples/firmware/baked/spot_classes.rs
diff -q "$bake/small/spot.rs" examples/firmware/baked/small/spot.rs
rm -r "$bake"
echo "baked Spot up to date"

step "firmware crate: rustfmt and clippy (it is outside the workspace)"
(
  cd examples/firmware
  cargo fmt --check
  # The target dir first: on a fresh clone the two clippy lists below
  # would both create it, each cargo by a temporary dir renamed into
  # place, and the rename of `target` can drop the other's `target/lint-b`
  # ("No such file or directory", seen 2026-12-07).
  mkdir -p target
  lint() { # TARGET [CARGO ARGS...]: one build's clippy, warnings denied
    local t=$1
    shift
    cargo clippy -q --release --target "$t" "$@" -- -D warnings
  }
  lint_board() { # TARGET: the builds every board has
    lint "$1"
    lint "$1" --features no-depth,flat
    lint "$1" --features immediate
    lint "$1" --features clipless
    lint "$1" --features tiles,inv-w
    lint "$1" --features clipless,inv-w
    lint "$1" --features subpixel4,depth-u32,no-i32-edges
    lint "$1" --no-default-features --features micromath
    for v in spot-flat spot-gouraud spot-lit spot-textured spot-textured-lit spot-phong; do
      lint "$1" --features "$v"
    done
  }
  # Two lists at once, the second with a target dir of its own: checking
  # the core is one rustc process, so one list leaves a core idle.
  (
    export CARGO_TARGET_DIR=target/lint-b
    lint_board thumbv6m-none-eabi
    # The herd of Spots, with and without occlusion culling, and the
    # house, with and without portal culling: the MPS2 boards only.
    lint thumbv7em-none-eabihf --features spot-flat,herd
    lint thumbv7em-none-eabihf --features spot-lit,herd-occlusion
    lint thumbv7em-none-eabihf --features house
    lint thumbv7em-none-eabihf --features house-portals
  ) &
  second=$!
  lint_board thumbv7em-none-eabihf
  # Cluster culling and normal masks of Spot: the MPS2 boards only (all
  # of Spot).
  lint thumbv7em-none-eabihf --features spot-lit,cull-volumes
  lint thumbv7em-none-eabihf --features spot-lit,cull-masks
  lint thumbv7em-none-eabihf --features spot-flat,cull-masks-frame
  wait "$second"
)

expected() { awk -v k="$1" '$1 == k { print $2 }' "$root/examples/firmware/host-checksums.txt"; }
want_depth=$(expected depth-u16)
want_nodepth=$(expected no-depth)
test -n "$want_depth" && test -n "$want_nodepth"

boards=(
  "thumbv7em-none-eabihf mps2-an386"
  "thumbv7m-none-eabi mps2-an385"
  "thumbv6m-none-eabi microbit"
)
variants=("" "flat" "no-depth" "no-depth,flat" "immediate")
# Spot (baked, immediate mode), one shading variant each; the micro:bit
# draws the decimated bake, so its checksums have keys of their own.
spot_variants=(spot-flat spot-gouraud spot-lit spot-textured spot-textured-lit spot-phong)
# Spot in cluster order with the cluster tests (docs/culling.md), with normal
# masks, the herd with and without occlusion culling, and the house with
# and without portal culling: the M4F only.
cluster_variants=(spot-flat,clusters spot-flat,cull-volumes spot-flat,cull-volumes-tree spot-flat,cull-cones spot-lit,clusters spot-lit,cull-volumes)
mask_variants=(spot-flat,cull-masks spot-flat,cull-masks-frame spot-lit,cull-masks spot-lit,cull-masks-frame)
herd_variants=(spot-flat,herd spot-flat,herd-occlusion)
house_variants=(house house-portals)
table_header="| board | features | flash B | statics B | stack B | RAM B | pixels written | instructions/frame | display push | render | clears | geometry (all strips) | rasterization | render instr/px |"
# Columns 8-13 of the table (frame, display push, render, clears,
# geometry, rasterization) are the instruction counts of record.
record=$root/docs/embedded.md
tolerance_pct=${FIRMWARE_COUNT_TOLERANCE_PCT:-1}
slack=4000

# The figures of one firmware run's output `$1`, into globals: frame,
# pixels, display, render, render_px, clears, geometry (set up
# once, or "x N strips" estimated), raster, statics, stack, ram.
parse_run() {
  local out=$1
  frame=$(sed -n 's/^instructions per frame \([0-9]*\);.*/\1/p' "$out")
  pixels=$(sed -n 's/.*pixels written \([0-9]*\);.*/\1/p' "$out")
  display=$(sed -n 's/^ *display push (checksum) *\([0-9]*\) .*/\1/p' "$out")
  render=$(sed -n 's/^ *render *\([0-9]*\) (.*/\1/p' "$out")
  render_px=$(sed -n 's/^ *render *[0-9]* (\([0-9.]*\)\/px)$/\1/p' "$out")
  clears=$(sed -n 's/^ *strip clears *\([0-9]*\) .*/\1/p' "$out")
  geometry=$(sed -n -E 's/^ *geometry (x [0-9]+ strips|\(once\)) +([0-9]+) .*/\2/p' "$out")
  raster=$(sed -n 's/^ *rasterization *\([0-9]*\) .*/\1/p' "$out")
  statics=$(sed -n 's/^ram statics \([0-9]*\) B.*/\1/p' "$out")
  stack=$(sed -n 's/.*stack high-water \([0-9]*\) B.*/\1/p' "$out")
  ram=$((statics + stack))
}

# Fails (returns 1) when the last parsed run of board `$1`, build `$2`,
# uses more RAM than the board's budget (16 KB on the micro:bit, 24 KB on
# the MPS2 boards).
check_ram() {
  local budget
  case $1 in microbit) budget=16384 ;; *) budget=24576 ;; esac
  if [ "$ram" -gt "$budget" ]; then
    echo "FAIL: $1 $2 uses $ram B of RAM, over the $budget B budget"
    return 1
  fi
}

# check_counts BOARD FEATURES "frame push render clears geometry raster":
# fails if any count grew by more than tolerance_pct (and more than the
# measurement's granularity, `slack` instructions) over the row recorded
# in docs/embedded.md (a missing row fails too).
check_counts() {
  local recorded
  recorded=$(awk -F'|' -v b=" $1 " -v f=" $2 " \
    '$2 == b && $3 == f { gsub(/[ *,]/, ""); print $9, $10, $11, $12, $13, $14; exit }' "$record")
  compare_counts "$1" "$2" "" "frame display-push render clears geometry rasterization" "$recorded" "$3"
}
# compare_counts BOARD NAME KIND "LABELS" "RECORDED" "NOW": the check of
# check_counts, check_config and check_sweep, count by count (KIND names
# the row in the message: "", "configuration " or "sweep ").
compare_counts() {
  local board=$1 name=$2 kind=$3 labels recorded=$5 now=$6 i bad=0
  if [ -z "$recorded" ]; then
    echo "FAIL: no ${kind}row for $board $name in docs/embedded.md"
    return 1
  fi
  read -r -a labels <<<"$4"
  read -r -a was <<<"$recorded"
  read -r -a is <<<"$now"
  for i in "${!labels[@]}"; do
    # SysTick ticks are 40 (62.5 on the micro:bit) instructions and the
    # clears are one strip's count times the strips, so a count can move
    # by a few thousand without any code change: that much is slack too.
    if [ $(( is[i] * 100 )) -gt $(( was[i] * (100 + tolerance_pct) )) ] && [ $(( is[i] - was[i] )) -gt "$slack" ]; then
      echo "FAIL: $board $name ${labels[i]} ${is[i]} instructions, over 1.0${tolerance_pct}x the recorded ${was[i]}"
      bad=1
    elif [ $(( is[i] * 100 )) -lt $(( was[i] * (100 - tolerance_pct) )) ] && [ $(( was[i] - is[i] )) -gt "$slack" ]; then
      echo "note: $board $name ${labels[i]} ${is[i]}, below the recorded ${was[i]}: update docs/embedded.md"
    fi
  done
  return "$bad"
}
# shade_fns ELF: the lighting and texture functions of the core's shading
# module that the ELF's debug info names (out of line or inlined), one a
# line: "lighting NAME" or "texture NAME".
shade_fns() {
  arm-none-eabi-objdump --dwarf=info "$1" | awk '/DW_AT_linkage_name/ { print $NF }' |
    arm-none-eabi-c++filt | sed 's/::h[0-9a-f]\{16\}$//' | sort -u | awk '
      /microraster::shade::(Lighting|LitColors|Phong|ColorNormal|ColorUvNormal|normalize|powi|pixel_normal)/ { print "lighting", $0 }
      /microraster::shade::(Texture|Textured|ColorUv|Phong<microraster::shade::Texture)/ { print "texture", $0 }'
}

# check_linked BOARD VARIANT FNS: an unlit variant links no lighting code
# and an untextured one no texture code (and the others do, so the check
# is not vacuous); FNS is the file of the ELF's shade_fns.
check_linked() {
  local board=$1 v=$2 fns lit tex
  fns=$(cat "$3")
  lit=$(grep -c '^lighting' <<<"$fns" || true)
  tex=$(grep -c '^texture' <<<"$fns" || true)
  case $v in spot-lit | spot-textured-lit | spot-phong) want_lit=1 ;; *) want_lit=0 ;; esac
  case $v in spot-textured | spot-textured-lit | spot-phong) want_tex=1 ;; *) want_tex=0 ;; esac
  echo "linked: $lit lighting and $tex texture functions of microraster::shade"
  if [ "$want_lit" = 0 ] && [ "$lit" != 0 ]; then
    echo "FAIL: $board $v is unlit but links lighting code:"; grep '^lighting' <<<"$fns"; return 1
  fi
  if [ "$want_tex" = 0 ] && [ "$tex" != 0 ]; then
    echo "FAIL: $board $v is untextured but links texture code:"; grep '^texture' <<<"$fns"; return 1
  fi
  if { [ "$want_lit" = 1 ] && [ "$lit" = 0 ]; } || { [ "$want_tex" = 1 ] && [ "$tex" = 0 ]; }; then
    echo "FAIL: $board $v: no lighting or texture function found where one must be (is the check broken?)"
    return 1
  fi
}

# The configuration sweep (cubes, set up once), on the M4F and the M0:
# the report's eight configurations (subpixel bits 8 / 4, depth u16 / u32,
# float backend libm / micromath), and from the default S8 u16 libm no
# depth buffer and the i32 edge fast path off, 1/w depth (inv-w) and
# 32x32 tiles into a windowed display (tiles): 12 per board.
# "label|cargo arguments|key in host-checksums.txt|variant run to reuse":
# the default and no-depth runs of the cubes are two of them already.
config_boards=("thumbv7em-none-eabihf mps2-an386" "thumbv6m-none-eabi microbit")
configs=(
  "S8 u16 libm||depth-u16|default"
  "S4 u16 libm|--features subpixel4|cubes-s4|"
  "S8 u32 libm|--features depth-u32|cubes-u32|"
  "S8 none libm|--features no-depth|no-depth|no-depth"
  "S4 u32 libm|--features subpixel4,depth-u32|cubes-s4-u32|"
  "S8 u16 micromath|--no-default-features --features micromath|cubes-micromath|"
  "S4 u16 micromath|--no-default-features --features micromath,subpixel4|cubes-s4-micromath|"
  "S8 u32 micromath|--no-default-features --features micromath,depth-u32|cubes-u32-micromath|"
  "S4 u32 micromath|--no-default-features --features micromath,subpixel4,depth-u32|cubes-s4-u32-micromath|"
  "S8 u16 libm no-i32-edges|--features no-i32-edges|depth-u16|"
  "S8 u16 libm inv-w|--features inv-w|inv-w|"
  "S8 u16 libm tiles 32x32|--features tiles|depth-u16|"
)

log=$root/target/firmware
mkdir -p "$log"
rows=()
failed=0

# Every build and QEMU run first, FIRMWARE_JOBS at once (default: the
# cores, at most 4): a build's LTO and codegen (one codegen unit) and a
# QEMU run each use one core. Each worker builds in a target dir of its
# own and stores what the checks below read: the run's output `$out`, its
# exit code `$out.rc`, the ELF's `arm-none-eabi-size` line `$out.size`
# and, for Spot's shading variants, its shading functions `$out.fns`. The
# checks then go through the runs in order. Instruction counts do not
# depend on the host's load (-icount shift=0).
jobs_list=$log/jobs.txt
: >"$jobs_list"
add_job() { # TARGET OUT "CARGO ARGS" [fns]
  printf '%s|%s|%s|%s\n' "$1" "$2" "$3" "${4:-}" >>"$jobs_list"
}
for b in "${boards[@]}"; do
  read -r target board <<<"$b"
  for features in "${variants[@]}"; do
    name=${features:-default}
    add_job "$target" "$log/$board-${name//,/+}.txt" "${features:+--features $features}"
  done
done
for b in "${config_boards[@]}"; do
  read -r target board <<<"$b"
  for c in "${configs[@]}"; do
    IFS='|' read -r label args key reuse <<<"$c"
    [ -n "$reuse" ] || add_job "$target" "$log/$board-config-${label// /-}.txt" "$args"
  done
  add_job "$target" "$log/$board-clipless.txt" "--features clipless"
done
for b in "${boards[@]}"; do
  read -r target board <<<"$b"
  for v in "${spot_variants[@]}"; do
    add_job "$target" "$log/$board-$v.txt" "--features $v" fns
  done
done
for v in "${cluster_variants[@]}" "${mask_variants[@]}" "${herd_variants[@]}" "${house_variants[@]}"; do
  add_job thumbv7em-none-eabihf "$log/mps2-an386-${v//,/+}.txt" "--features $v"
done
rm -f "$log/queue.next" "$log"/*.rc "$log"/*.size "$log"/*.fns
echo 1 >"$log/queue.next"
# The next job's line in the list (under a lock where there are workers
# beside this one; util-linux's flock).
take_job() {
  local next='n=$(cat "$1"); echo $((n + 1)) >"$1"; echo "$n"'
  if [ "$workers" -gt 1 ]; then
    flock "$log/queue.lock" bash -c "$next" _ "$log/queue.next"
  else
    bash -c "$next" _ "$log/queue.next"
  fi
}
# WORKER: takes the next job of the list until none is left. Each job is
# the documented command (`cargo run --release --target T --features F`);
# the runner in .cargo/config.toml starts QEMU under `timeout 300`, and
# the outer timeout covers the build too.
fw_worker() {
  local dir=$root/examples/firmware/target/w$1 n line target out args fns rc elf
  while :; do
    n=$(take_job)
    line=$(sed -n "${n}p" "$jobs_list")
    [ -n "$line" ] || return 0
    IFS='|' read -r target out args fns <<<"$line"
    # shellcheck disable=SC2086 # $args is a list of cargo arguments
    (cd "$root/examples/firmware" && CARGO_TARGET_DIR=$dir timeout 900 \
      cargo run -q --release --target "$target" $args </dev/null >"$out" 2>&1)
    rc=$?
    elf=$dir/$target/release/microraster-firmware
    if [ "$rc" = 0 ]; then
      arm-none-eabi-size "$elf" | tail -1 >"$out.size"
      [ -z "$fns" ] || shade_fns "$elf" >"$out.fns"
    fi
    echo "$rc" >"$out.rc"
  done
}
workers=${FIRMWARE_JOBS:-$(nproc)}
[ "$workers" -le 4 ] || workers=4
command -v flock >/dev/null || workers=1
step "building and running $(wc -l <"$jobs_list") firmware builds, $workers at once"
pids=()
for ((w = 0; w < workers; w++)); do
  (set +e; fw_worker "$w") &
  pids+=($!)
done
for p in "${pids[@]}"; do wait "$p"; done
echo "done in ${SECONDS}s"
# The exit code of the run whose output is `$1` ("missing": none ran).
ran() { cat "$1.rc" 2>/dev/null || echo missing; }

cd examples/firmware
for b in "${boards[@]}"; do
  read -r target board <<<"$b"
  for features in "${variants[@]}"; do
    name=${features:-default}
    step "$board ($target), features: $name"
    out=$log/$board-${name//,/+}.txt
    rc=$(ran "$out")
    cat "$out"
    if [ "$rc" != 0 ]; then
      echo "FAIL: $board $name exited $rc"
      failed=1
      continue
    fi
    got=$(awk '$1 == "checksum" { print $2 }' "$out")
    case $features in
      *no-depth*) want=$want_nodepth ;;
      *) want=$want_depth ;;
    esac
    if [ "$got" != "$want" ]; then
      echo "FAIL: $board $name checksum $got, host-checksums.txt says $want"
      failed=1
    fi
    read -r text data bss _ <"$out.size"
    parse_run "$out"
    check_ram "$board" "$name" || failed=1
    row="| $board | $name | $((text + data)) | $statics | $stack | $ram | $pixels | $frame | $display | $render | $clears | $geometry | $raster | $render_px |"
    rows+=("$row")
    # The counts of record: docs/embedded.md's row for this board and
    # variant. QEMU's counts are deterministic, so any growth is real.
    check_counts "$board" "$name" "$frame $display $render $clears $geometry $raster" || failed=1
  done
done

config_header="| board | configuration | frame | render | rasterization | RAM B |"
config_rows=()
# check_config BOARD LABEL "frame render raster": the 1 % check of
# check_counts against docs/embedded.md's configuration table.
check_config() {
  local recorded
  recorded=$(awk -F'|' -v b=" $1 " -v f=" $2 " \
    '$2 == b && $3 == f { gsub(/[ *,]/, ""); print $4, $5, $6; exit }' "$record")
  compare_counts "$1" "$2" "configuration " "frame render rasterization" "$recorded" "$3"
}
for b in "${config_boards[@]}"; do
  read -r target board <<<"$b"
  for c in "${configs[@]}"; do
    IFS='|' read -r label args key reuse <<<"$c"
    step "$board ($target), configuration: $label"
    if [ -n "$reuse" ]; then
      out=$log/$board-$reuse.txt
      echo "(the $reuse run above)"
      if ! grep -q '^PASS' "$out"; then
        echo "FAIL: $board $label: the $reuse run did not pass"
        failed=1
        continue
      fi
    else
      out=$log/$board-config-${label// /-}.txt
      rc=$(ran "$out")
      cat "$out"
      if [ "$rc" != 0 ]; then
        echo "FAIL: $board $label exited $rc"
        failed=1
        continue
      fi
    fi
    got=$(awk '$1 == "checksum" { print $2 }' "$out")
    want=$(expected "$key")
    if [ -z "$want" ] || [ "$got" != "$want" ]; then
      echo "FAIL: $board $label checksum $got, host-checksums.txt says ${want:-nothing} ($key)"
      failed=1
    fi
    parse_run "$out"
    check_ram "$board" "$label" || failed=1
    config_rows+=("| $board | $label | $frame | $render | $raster | $ram |")
    check_config "$board" "$label" "$frame $render $raster" || failed=1
  done
done

# spot_run TARGET BOARD FEATURES KEY ROWS: builds and runs a Spot variant,
# requires exit 0 and the checksum of host-checksums.txt's KEY, checks
# its RAM and its counts of record, and appends its table row to the
# array named ROWS. Returns 1 when the run itself failed (nothing to
# check further).
spot_run() {
  local target=$1 board=$2 v=$3 key=$4
  local -n table=$5
  case $v in house*) step "$board ($target), the house: $v" ;; *) step "$board ($target), Spot: $v" ;; esac
  out=$log/$board-${v//,/+}.txt
  rc=$(ran "$out")
  cat "$out"
  if [ "$rc" != 0 ]; then
    echo "FAIL: $board $v exited $rc"
    failed=1
    return 1
  fi
  got=$(awk '$1 == "checksum" { print $2 }' "$out")
  want=$(expected "$key")
  if [ -z "$want" ] || [ "$got" != "$want" ]; then
    echo "FAIL: $board $v checksum $got, host-checksums.txt says ${want:-nothing} ($key)"
    failed=1
  fi
  read -r text data bss _ <"$out.size"
  parse_run "$out"
  check_ram "$board" "$v" || failed=1
  table+=("| $board | $v | $((text + data)) | $statics | $stack | $ram | $pixels | $frame | $display | $render | $clears | $geometry | $raster | $render_px |")
  check_counts "$board" "$v" "$frame $display $render $clears $geometry $raster" || failed=1
}

spot_rows=()
for b in "${boards[@]}"; do
  read -r target board <<<"$b"
  for v in "${spot_variants[@]}"; do
    case $board in microbit) key=$v-microbit ;; *) key=$v ;; esac
    spot_run "$target" "$board" "$v" "$key" spot_rows || continue
    check_linked "$board" "$v" "$out.fns" || failed=1
  done
done

# Cluster culling of Spot (issue 11) on the M4F: Spot in cluster order
# (baked/spot_clusters.rs), the baseline with every cluster drawn and the
# three cluster tests; each frame bit-identical to the host's unculled
# one (build.rs) and to host-checksums.txt, counts of record in
# docs/embedded.md.
# check_sweep BOARD NAME "CULLED EVERY": a camera sweep's mean render
# instructions a frame, culled and with every cluster drawn, against the
# sweep table of docs/embedded.md (as check_counts).
check_sweep() {
  local recorded
  recorded=$(awk -F'|' -v b=" $1 " -v f=" $2 " \
    '$2 == b && $3 == f { gsub(/[ *,]/, ""); print $7, $8; exit }' "$record")
  compare_counts "$1" "$2" "sweep " "culled every-cluster" "$recorded" "$3"
}
cluster_rows=()
sweep_rows=()
for v in "${cluster_variants[@]}"; do
  spot_run thumbv7em-none-eabihf mps2-an386 "$v" "${v%%,*}-clusters" cluster_rows || continue
  case $v in *cull-*)
    if ! grep -q 'skipped before transform [1-9]' "$out"; then
      echo "FAIL: mps2-an386 $v skipped no triangle"
      failed=1
    fi ;;
  esac
  # The camera sweep: cameras round Spot, each frame drawn culled and with
  # every cluster and compared on the board (a difference fails the run).
  sweep=$(sed -nE 's/^sweep of ([0-9]+) cameras: skipped before transform ([0-9.]+) % \(([0-9.]+)-([0-9.]+) %\); render a frame ([0-9]+) culled, ([0-9]+) with every cluster \(([0-9.]+)x\)$/\1 \2 \3 \4 \5 \6 \7/p' "$out")
  if [ -z "$sweep" ]; then
    echo "FAIL: mps2-an386 $v printed no camera sweep"
    failed=1
    continue
  fi
  read -r cams mean lo hi culled every ratio <<<"$sweep"
  sweep_rows+=("| mps2-an386 | $v (sweep) | $cams | $mean % | $lo-$hi % | $culled | $every | $ratio |")
  check_sweep mps2-an386 "$v (sweep)" "$culled $every" || failed=1
done

# Normal masks of Spot (issue 11) on the M4F: the Morton order of the
# shading rows, each strip's own mask (its rows, the lecture's sectors)
# or one mask a frame; each frame must be the unmasked one
# (host-checksums.txt), counts of record in docs/embedded.md.
mask_rows=()
for v in "${mask_variants[@]}"; do
  spot_run thumbv7em-none-eabihf mps2-an386 "$v" "${v%%,*}" mask_rows || continue
  if ! grep -qE '^normal masks .*: masked [1-9]' "$out"; then
    echo "FAIL: mps2-an386 $v masked no triangle"
    failed=1
  fi
done

# Occlusion culling (issue 11) on the M4F: a herd of 100 Spots, each
# strip drawing them front to back plainly (`herd`) or through an
# `Occluder` (`herd-occlusion`); both frames must be the herd's host
# frame (host-checksums.txt `spot-flat-herd`), counts of record in
# docs/embedded.md, and the occlusion build must hide something, and
# print its sweep of 64 cameras (each frame drawn with the test and
# without; the firmware fails if any pair differs).
herd_rows=()
for v in "${herd_variants[@]}"; do
  spot_run thumbv7em-none-eabihf mps2-an386 "$v" spot-flat-herd herd_rows || continue
  case $v in *herd-occlusion)
    if ! grep -qE '^herd of [0-9]+ Spots: hidden by occlusion before transform [1-9]' "$out"; then
      echo "FAIL: mps2-an386 $v hid no triangle"
      failed=1
    fi
    if ! grep -E '^herd sweep of 64 cameras: hidden by occlusion before transform [1-9]' "$out"; then
      echo "FAIL: mps2-an386 $v printed no herd sweep that hid anything"
      failed=1
    fi
    ;;
  esac
done

# Portal culling (issue 11) on the M4F: the host's 8x8 house
# (baked/house.rs, `microraster bake-house`), every room in every strip
# (`house`) or the rooms whose rectangle from the portal walk meets the
# strip (`house-portals`); both frames must be the house drawn whole
# (host-checksums.txt `house`, which std-host/tests/portal.rs computes
# from the generator), counts of record in docs/embedded.md. The portal
# build must skip something, and its sweep of 64 cameras compares each
# culled frame with the whole one on the board (a difference fails it).
house_rows=()
house_sweep_rows=()
for v in "${house_variants[@]}"; do
  spot_run thumbv7em-none-eabihf mps2-an386 "$v" house house_rows || continue
  case $v in house-portals)
    if ! grep -qE '^portals: [0-9]+ of [0-9]+ rooms reached, skipped before transform [1-9]' "$out"; then
      echo "FAIL: mps2-an386 $v skipped no triangle"
      failed=1
    fi
    sweep=$(sed -nE 's/^sweep of ([0-9]+) cameras: ([0-9.]+) rooms reached, skipped before transform ([0-9.]+) %; render a frame ([0-9]+) culled, ([0-9]+) with every room \(([0-9.]+)x\)$/\1 \2 \3 \4 \5 \6/p' "$out")
    if [ -z "$sweep" ]; then
      echo "FAIL: mps2-an386 $v printed no camera sweep"
      failed=1
      continue
    fi
    read -r cams reached mean culled every ratio <<<"$sweep"
    house_sweep_rows+=("| mps2-an386 | $v (sweep) | $cams | $mean % | $reached | $culled | $every | $ratio |")
    check_sweep mps2-an386 "$v (sweep)" "$culled $every" || failed=1
    ;;
  esac
done

# The clipless mode (issue 12): the cubes in immediate mode on the M4F and
# the M0, bit-identical to the host's clipless frame, counts of record in
# docs/embedded.md like the rows above.
clipless_rows=()
for b in "thumbv7em-none-eabihf mps2-an386" "thumbv6m-none-eabi microbit"; do
  read -r target board <<<"$b"
  step "$board ($target), clipless"
  out=$log/$board-clipless.txt
  rc=$(ran "$out")
  cat "$out"
  if [ "$rc" != 0 ]; then
    echo "FAIL: $board clipless exited $rc"
    failed=1
    continue
  fi
  got=$(awk '$1 == "checksum" { print $2 }' "$out")
  want=$(expected clipless)
  if [ -z "$want" ] || [ "$got" != "$want" ]; then
    echo "FAIL: $board clipless checksum $got, host-checksums.txt says ${want:-nothing}"
    failed=1
  fi
  read -r text data bss _ <"$out.size"
  parse_run "$out"
  check_ram "$board" clipless || failed=1
  clipless_rows+=("| $board | clipless | $((text + data)) | $statics | $stack | $ram | $pixels | $frame | $display | $render | $clears | $geometry | $raster | $render_px |")
  check_counts "$board" clipless "$frame $display $render $clears $geometry $raster" || failed=1
  # The report's mode axis: this run and the immediate build's above.
  check_config "$board" "S8 u16 libm clipless" "$frame $render $raster" || failed=1
  if [ -f "$log/$board-immediate.txt" ]; then
    parse_run "$log/$board-immediate.txt"
    check_config "$board" "S8 u16 libm immediate" "$frame $render $raster" || failed=1
  fi
done
cd "$root"

step "clipless mode (320x240 Rgb565, u16 depth, immediate; the same table in docs/embedded.md)"
echo "$table_header"
echo "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
printf '%s\n' "${clipless_rows[@]}"

step "budget table (320x240 Rgb565, four cubes; paste into docs/embedded.md when the counts change)"
echo "$table_header"
echo "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
printf '%s\n' "${rows[@]}"

step "Spot, shading variants (320x240 Rgb565, u16 depth, immediate; the same table in docs/embedded.md)"
echo "$table_header"
echo "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
printf '%s\n' "${spot_rows[@]}"

step "Spot, cluster culling on the M4F (the same table in docs/embedded.md and docs/culling.md)"
echo "$table_header"
echo "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
printf '%s\n' "${cluster_rows[@]}"

step "Spot, normal masks on the M4F (the same table in docs/embedded.md)"
echo "$table_header"
echo "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
printf '%s\n' "${mask_rows[@]}"

step "Spot herd, occlusion culling on the M4F (the same table in docs/embedded.md)"
echo "$table_header"
echo "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
printf '%s\n' "${herd_rows[@]}"

step "the house, portal culling on the M4F (the same table in docs/embedded.md)"
echo "$table_header"
echo "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
printf '%s\n' "${house_rows[@]}"

step "the house, portal culling on the M4F, camera sweep (the same table in docs/embedded.md)"
echo "| board | build | cameras | skipped before transform, mean | rooms reached, mean | render a frame, culled | with every room | culled / every |"
echo "|---|---|---:|---:|---:|---:|---:|---:|"
printf '%s\n' "${house_sweep_rows[@]}"

step "Spot, cluster culling on the M4F, camera sweep (the same table in docs/embedded.md)"
echo "| board | build | cameras | skipped before transform, mean | fewest-most | render a frame, culled | with every cluster | culled / every |"
echo "|---|---|---:|---:|---:|---:|---:|---:|"
printf '%s\n' "${sweep_rows[@]}"

step "configurations, the report's speed axis (cubes, set up once; the same table in docs/embedded.md)"
echo "$config_header"
echo "|---|---|---:|---:|---:|---:|"
printf '%s\n' "${config_rows[@]}"

if [ "$failed" -ne 0 ]; then
  echo
  echo "firmware: FAILED"
  exit 1
fi
echo
echo "firmware: all boards passed"
