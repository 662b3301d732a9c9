#!/usr/bin/env bash
# The fault matrix of issues 18 and 37: runs `envmis` as a user would against full disks,
# signals, killed runs, special files, absurd sizes, unwritable standard output,
# overflowing maps, outputs that are inputs, absurd option values, corrupted and crafted
# tables, special and huge inputs, stale library tables and hostile file names, and
# prints one row per case: what was tried, the exit code, the seconds it took, what it
# left in its folder, and a verdict:
#   clean error        non-zero exit (a one-line message), nothing left at the destination
#   clean stop         a signalled run exited 130/143 within 2 s and left nothing unmarked
#   ok                 a case expected to succeed did, leaving no temporary
#   skipped            the machine cannot set the case up (exit 77)
#   wrong success      exit 0 where the run could not have succeeded
#   input changed      an input (a file named in.*, or in a folder named in.*) is not
#                      byte-identical afterwards, or is gone
#   crash              killed by a signal it did not handle (or sanitizer/abort)
#   hang / slow        ran past its time limit / a signal took more than 2 s to act on
#   leftovers          the run left a partial or temporary file behind
#   failed             a case expected to succeed did not (or its set-up failed)
#   unnamed            the error does not name the file it is about
#   stale              a library run kept the old table of a map that now fails, unsaid
#   raw control chars  standard error holds a raw ESC or BEL byte (terminal injection)
#   exit N             a signalled run exited with the wrong status
# A case's class is the first word of its name; the run ends with a table of the cases
# and verdicts of each class, the failing cases with the first line of their standard
# error, and exits 1 when any verdict is bad (anything but clean error, clean stop, ok,
# skipped), else 0.
# Usage: scripts/faults.sh [path/to/envmis]   (default build/apps/envmis)
#        FAULTS_ONLY=REGEX scripts/faults.sh ...  runs only the cases whose names match
#        FAULTS_VERBOSE=1 scripts/faults.sh ...   also prints each case's first line of stderr
# Every output is bounded: file sizes by `ulimit -f`, runs by `timeout`.
set -uo pipefail
cd "$(dirname "$0")/.."
cli=$(realpath "${1:-build/apps/envmis}")
[[ -x $cli ]] || { echo "faults.sh: $cli: not an executable" >&2; exit 2; }
export OCIO=${OCIO:-$PWD/data/ocio/config.ocio}
maps=$PWD/data/envmaps
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
ulimit -c 0
ulimit -f 4194304  # 4 GiB (bash counts KiB): no case writes more; the full-disk cases set their own
started=$SECONDS

printf '%-62s %5s %5s  %-17s %s\n' case exit secs verdict leftovers
declare -A cases_of=() count=() seen=()
classes=() verdicts=() bad_rows=()
# The first line of a standard error file that is not a progress line, shown safely.
first_line() { grep -avE '^[[:alnum:] ._-]+ +[0-9]+%$' "$1" | head -n 1 | head -c 200 | cat -v; }
# A verdict that is not a failure.
good() { [[ $1 == "clean error" || $1 == "clean stop" || $1 == ok || $1 == skipped ]]; }
# One row, counted in its class (the name's first word); arguments: name, exit, seconds,
# verdict, leftovers, and the file holding the case's standard error.
row() {
  printf '%-62s %5s %5s  %-17s %s\n' "$1" "$2" "$3" "$4" "$5"
  [[ -n ${FAULTS_VERBOSE:-} && -n ${6:-} && -s $6 ]] && echo "      stderr: $(first_line "$6")"
  local class=${1%% *}
  [[ -v cases_of[$class] ]] || { classes+=("$class"); cases_of[$class]=0; }
  [[ -v seen[$4] ]] || { verdicts+=("$4"); seen[$4]=1; }
  cases_of[$class]=$((cases_of[$class] + 1))
  count[$class/$4]=$((${count[$class/$4]:-0} + 1))
  if ! good "$4"; then
    local first=""
    [[ -n ${6:-} && -f $6 ]] && first=$(first_line "$6")
    bad_rows+=("$1 | $4 | ${first:-(no stderr)}")
  fi
}

# The files a case left in its folder: not its inputs (named in.*) and not the files its
# set-up made (listed in DIR.list).
leftovers() {
  local list=$1.list
  [[ -f $list ]] || list=/dev/null
  (cd "$1" && find . -mindepth 1 ! -type d ! -name 'in.*' -print | grep -vxF -f "$list" | sed 's|^\./||' |
    tr '\n' ' ' | head -c 200)
}

# True where standard error ($1) holds a raw ESC or BEL byte.
raw_controls() { [[ $(tr -dc '\033\007' <"$1" | head -c 1 | wc -c) != 0 ]]; }

# Runs one case in a fresh folder: expect "error" (must fail cleanly) or "ok" (must exit 0
# and leave no temporary). Files named in.* are the case's own inputs and not counted; a
# command exits 77 when the machine cannot set the case up (mknod without privilege).
# Arguments: name, expect, limit in seconds, then a shell command run in the folder.
# Optional variables, given as prefixes (`pre=... case_ ...`):
#   pre    a set-up command run in the folder first: what it makes is not counted as
#          left over; its inputs (in.*, and files in folders named in.*) are saved and must
#          be byte-identical after the case ("input changed")
#   check  a command run in the folder after the case; where it fails the verdict is $bad
#   bad    that verdict (e.g. unnamed, stale)
case_() {
  [[ $1 =~ ${FAULTS_ONLY:-.} ]] || return 0
  local name=$1 expect=$2 limit=$3 dir=$work/$RANDOM$RANDOM
  shift 3
  mkdir -p "$dir/out" "$dir.orig" && cp "$maps/studio.exr" "$dir/in.exr"
  if [[ -n ${pre:-} ]] && ! (cd "$dir" && timeout -s KILL 120 bash -c "$pre" >/dev/null 2>"$dir/in.err") 2>/dev/null
  then
    row "$name" - 0 failed "(set-up failed)" "$dir/in.err"
    rm -rf "$dir" "$dir.orig" "$dir.list"
    return
  fi
  # What the set-up made, and a copy of every regular input file.
  (cd "$dir" && find . -mindepth 1 ! -type d -print >"$dir.list" &&
    find -L . -type f ! -path ./in.err \( -name 'in.*' -o -path './in.*/*' \) -print0 |
    xargs -0r cp -L --parents -t "$dir.orig/") 2>/dev/null
  local start=$SECONDS rc
  (cd "$dir" && timeout -s KILL "$limit" bash -c "$*" >/dev/null 2>"$dir/in.err") 2>/dev/null
  rc=$?
  local secs=$((SECONDS - start)) left verdict changed="" f
  left=$(leftovers "$dir")
  while IFS= read -r -d '' f; do
    cmp -s "$dir.orig/$f" "$dir/$f" || changed+="${f#./} "
  done < <(cd "$dir.orig" && find . -type f -print0)
  if ((rc == 77)); then verdict=skipped
  elif [[ -n $changed ]]; then verdict="input changed" left="changed: $(printf %s "$changed" | cat -v) $left"
  elif ((rc == 137)); then verdict=hang
  elif ((rc >= 128)); then verdict=crash
  elif [[ $expect == error && $rc == 0 ]]; then verdict="wrong success"
  elif [[ $expect == ok && $rc != 0 ]]; then verdict=failed
  elif [[ -n ${check:-} ]] && ! (cd "$dir" && bash -c "$check") >/dev/null 2>&1; then verdict=${bad:-failed}
  elif raw_controls "$dir/in.err"; then verdict="raw control chars"
  elif [[ $expect == error && -n $left ]]; then verdict=leftovers
  elif [[ $expect == error ]]; then verdict="clean error"
  elif [[ $left == *.tmp* ]]; then verdict=leftovers
  else verdict=ok
  fi
  row "$name" "$rc" "$secs" "$verdict" "$(printf %s "$left" | cat -v)" "$dir/in.err"
  rm -rf "$dir" "$dir.orig" "$dir.list"
}

# A run signalled after `delay` seconds; it must exit 128 + signal within 2 s. It is
# waited for at most $wait_s seconds after the signal (default 60), then killed ("hang").
# With $after (a regex), the run prints its progress lines (ENVMIS_PROGRESS=1) and the
# delay counts from the first line of standard error that matches it.
signal_case() {
  [[ $1 =~ ${FAULTS_ONLY:-.} ]] || return 0
  local name=$1 signal=$2 delay=$3 dir=$work/$RANDOM$RANDOM
  shift 3
  mkdir -p "$dir/out" && cp "$maps/studio.exr" "$dir/in.exr"
  [[ -f $work/big.exr ]] && ln -s "$work/big.exr" "$dir/in.big.exr"
  (cd "$dir" && ENVMIS_PROGRESS=${after:+1} exec "$cli" "$@" >/dev/null 2>"$dir/in.err") 2>/dev/null &
  local pid=$! tenths=0
  while [[ -n ${after:-} ]] && ! grep -qE "$after" "$dir/in.err" 2>/dev/null && kill -0 "$pid" 2>/dev/null &&
    ((tenths++ < 1200)); do sleep 0.1; done
  sleep "$delay"
  kill -"$signal" "$pid" 2>/dev/null
  local sent=$SECONDS waited=0
  while kill -0 "$pid" 2>/dev/null && ((waited < ${wait_s:-60})); do sleep 0.1; waited=$((SECONDS - sent)); done
  kill -KILL "$pid" 2>/dev/null
  wait "$pid"
  local rc=$? secs=$((SECONDS - sent)) left verdict want
  want=$([[ $signal == INT ]] && echo 130 || echo 143)
  left=$(leftovers "$dir")
  if ((rc == 0)); then verdict="wrong success"
  elif ((rc == 137)); then verdict=hang
  elif ((rc != want)); then verdict="exit $rc"
  elif ((secs > 2)); then verdict=slow
  elif [[ $left == *.tmp* ]]; then verdict=leftovers
  elif [[ -n $left ]] && grep -L partial "$dir"/out/* 2>/dev/null | grep -q .; then verdict=leftovers
  else verdict="clean stop"
  fi
  row "$name" "$rc" "$secs" "$verdict" "$left" "$dir/in.err"
  rm -rf "$dir"
}

# Inputs made once: an 8192x4096 map (a few seconds to load and precompute), a 1x65536
# map, a constant 3e38 map (PFM: finite floats whose sums overflow), a 32x16 map and its
# table (the tables class corrupts and crafts copies of it), images whose headers declare
# 30000x30000 and 40000x40000 pixels and hold none, and a compare run's JSON.
"$cli" convert "$maps/studio.exr" --from equirect --to equirect --size 8192x4096 -o "$work/big.exr" >/dev/null 2>&1
python3 - "$work" <<'PY'
import math, struct, sys
def pfm(path, w, h, value):
    with open(path, "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (w, h))
        f.write(struct.pack("<%df" % (3 * w * h), *([value] * (3 * w * h))))
pfm(sys.argv[1] + "/tall.pfm", 1, 65536, 1.0)
pfm(sys.argv[1] + "/huge.pfm", 64, 32, 3e38)
with open(sys.argv[1] + "/tiny.pfm", "wb") as f:  # a sky with a sun
    f.write(b"PF\n32 16\n-1.0\n")
    for y in range(16):
        for x in range(32):
            v = 0.2 + 0.1 * math.sin(x / 5.0) + (500.0 if (x, y) == (20, 12) else 0.0)
            f.write(struct.pack("<3f", v, 0.9 * v, 0.8 * v))
with open(sys.argv[1] + "/huge-header.hdr", "wb") as f:
    f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 30000 +X 30000\n")
with open(sys.argv[1] + "/huge-header.pfm", "wb") as f:
    f.write(b"PF\n40000 40000\n-1.0\n")
PY
"$cli" precompute "$work/tiny.pfm" -o "$work/tiny.envmis" >/dev/null 2>&1
"$cli" compare "$maps/studio.exr" --points 4 --spp 16 --json "$work/r.json" >/dev/null 2>&1
# The tables class's files: a truncated table, one with a flipped payload byte, a foreign
# file with only the magic, and crafted tables whose checksums are recomputed after a
# change (envmis::hash64, math/hash.h, reimplemented here and checked against the real
# table's own checksums first; where it does not match, the crafted cases are skipped).
mkdir -p "$work/tables"
[[ -s $work/tiny.envmis ]] || echo "faults.sh: precompute of a 32x16 map failed; the tables cases are skipped" >&2
[[ -s $work/tiny.envmis ]] && python3 - "$work/tiny.envmis" "$work/tables" <<'PY' ||
import struct, sys
M64 = (1 << 64) - 1
P = ((0x100000001b3 * 0x9e3779b97f4a7c15) & M64) | 1
def avalanche(x):
    x ^= x >> 33; x = (x * 0xff51afd7ed558ccd) & M64
    x ^= x >> 33; x = (x * 0xc4ceb9fe1a85ec53) & M64
    return x ^ (x >> 33)
def hash64(b):  # envmis::hash64: 4 lanes over 8-byte words, the zero-padded tail, the length
    lanes = [0xcbf29ce484222325, 0x84222325cbf29ce4, 0x9e3779b97f4a7c15, 0x7f4a7c159e3779b9]
    full = len(b) // 32 * 32
    data = bytes(b[:full]) + bytes(b[full:]) + bytes(32 - (len(b) - full))
    words = struct.unpack("<%dQ" % (len(data) // 8), data)
    for i in range(0, len(words), 4):
        for k in range(4):
            lanes[k] = ((lanes[k] ^ words[i + k]) * P) & M64
    out = len(b)
    for lane in lanes:
        out = avalanche(out ^ avalanche(lane))
    return out
src, out = open(sys.argv[1], "rb").read(), sys.argv[2] + "/"
open(out + "truncated.envmis", "wb").write(src[: len(src) // 2])
open(out + "magic-only.envmis", "wb").write(src[:8])
m = struct.unpack_from("<I", src, 24)[0]
w, h, kind, flags = struct.unpack_from("<4I", src, 32)
p0, p1 = 40 + m, 40 + m + 16 * w * h
flipped = bytearray(src); flipped[p0 + 4 * w * h + 40] ^= 0x40
open(out + "flipped.envmis", "wb").write(flipped)
if flags & 2 or len(src) != p1 + 8:
    sys.exit("tiny.envmis is compact or binned: no crafted tables")
if hash64(src[: 32 + m]) != struct.unpack_from("<Q", src, 32 + m)[0] or \
   hash64(src[p0:p1]) != struct.unpack_from("<Q", src, p1)[0]:
    sys.exit("hash64 reimplementation does not match the table's checksums: no crafted tables")
def crafted(name, change):
    t = bytearray(src)
    change(t)
    struct.pack_into("<Q", t, 32 + m, hash64(t[: 32 + m]))
    struct.pack_into("<Q", t, p1, hash64(t[p0:p1]))
    open(out + name + ".envmis", "wb").write(t)
fmax = struct.pack("<f", 3.4028234663852886e38)
crafted("crafted-threshold", lambda t: struct.pack_into("<f", t, 76, 1e30))       # threshold alpha * Lbar
crafted("crafted-luma", lambda t: struct.pack_into("<f", t, 52, 1e30))            # luma coefficient R
crafted("crafted-zero-density", lambda t: t.__setitem__(slice(p0, p0 + 4 * w * h), bytes(4 * w * h)))
crafted("crafted-fltmax-texel", lambda t: t.__setitem__(slice(p0 + 4 * w * h, p0 + 4 * w * h + 12), fmax * 3))
crafted("crafted-fltmax-all", lambda t: t.__setitem__(slice(p0 + 4 * w * h, p1), fmax * (3 * w * h)))
PY
  echo "faults.sh: crafting tables failed; the crafted cases are skipped" >&2
export EVIL=$'in.evil\e]0;owned\a.exr'  # a name with ESC and BEL (an xterm title escape)

# full: a full disk (a 100 KB file-size limit; SIGXFSZ is what the kernel sends past it).
case_ "full visualize -> PNG, disk full" error 120 "ulimit -f 100; $cli visualize in.exr -o out/x.png --panel-width 1024"
case_ "full compare --plots -> PNGs, disk full" error 300 "ulimit -f 4; $cli compare in.exr --points 4 --spp 16 --plots out"
case_ "full compare --images -> PNG, disk full" error 300 "ulimit -f 20; $cli compare in.exr --points 4 --spp 16 --images out"
case_ "full precompute -> table, disk full" error 120 "ulimit -f 100; $cli precompute in.exr -o out/t.envmis"
case_ "full convert -> EXR, disk full" error 120 "ulimit -f 100; $cli convert in.exr -o out/c.exr"
case_ "full compare --csv/--json, disk full" error 300 "ulimit -f 1; $cli compare in.exr --points 64 --spp 16 --csv out/c.csv --json out/c.json"

# signals.
signal_case "signals precompute 8k map, SIGINT at 1 s" INT 1 precompute in.big.exr -o out/t.envmis
signal_case "signals precompute 8k map --bins 121, SIGTERM at 3 s" TERM 3 precompute in.big.exr --bins 121 -o out/t.envmis
signal_case "signals convert --size 16384, SIGINT at 2 s" INT 2 convert in.exr --size 16384 -o out/c.exr
signal_case "signals compare --spp 1e9, SIGINT at 2 s" INT 2 compare in.exr --spp 1000000000 --points 100000 --json out/c.json --csv out/c.csv
signal_case "signals compare --spp 1e9, SIGTERM at 2 s" TERM 2 compare in.exr --spp 1000000000 --points 100000 --json out/c.json
signal_case "signals visualize 8k map, SIGTERM at 1 s" TERM 1 visualize in.big.exr -o out/v.png --panel-width 4096

# killed: a temporary left by a SIGKILL is gone after the next write.
case_ "killed SIGKILL mid-write, then rerun" ok 120 "ln -s $work/big.exr in.big.exr; ($cli precompute in.big.exr -o out/t.envmis & p=\$!;
  for i in \$(seq 600); do ls out/.t* >/dev/null 2>&1 && break; sleep 0.1; done; kill -KILL \$p; wait \$p;
  ls out/.t* >/dev/null 2>&1) || exit 77; $cli precompute in.exr -o out/t.envmis"

# special-out: -o onto special files.
case_ "special-out -o onto a FIFO" error 30 "mkfifo out/in.f.envmis; $cli precompute in.exr -o out/in.f.envmis"
case_ "special-out -o onto a symlink" error 30 "echo keep > in.target; ln -s ../in.target out/in.l.envmis; $cli precompute in.exr -o out/in.l.envmis"
case_ "special-out -o onto a character device" error 30 "mknod out/in.null.envmis c 1 3 || exit 77; $cli precompute in.exr -o out/in.null.envmis"
case_ "special-out rewrite keeps mode 0600" ok 60 "$cli precompute in.exr -o out/t.envmis && chmod 600 out/t.envmis && $cli precompute in.exr -o out/t.envmis && [ \$(stat -c %a out/t.envmis) = 600 ]"

# absurd: absurd sizes.
case_ "absurd visualize a 1x65536 map" error 60 "$cli visualize $work/tall.pfm -o out/v.png"
case_ "absurd convert --size 40000" error 60 "$cli convert in.exr --size 40000 -o out/c.exr"
case_ "absurd bench --size 65536x65536" error 60 "$cli bench --size 65536x65536"
case_ "absurd convert --size -1" error 60 "$cli convert in.exr --size -1 -o out/c.exr"
case_ "absurd compare --threads 4000" error 60 "$cli compare in.exr --points 2 --spp 4 --threads 4000"

# stdout: standard output that cannot be written.
case_ "stdout info > /dev/full" error 60 "$cli info in.exr > /dev/full"
# The table is complete and stays (named in.* so as not to count): only the report failed.
case_ "stdout precompute > /dev/full" error 60 "$cli precompute in.exr -o out/in.t.envmis > /dev/full"
case_ "stdout compare > /dev/full" error 120 "$cli compare in.exr --points 4 --spp 16 > /dev/full"

# overflow: a constant 3e38 map.
case_ "overflow compare on a constant 3e38 map" error 120 "$cli compare $work/huge.pfm --points 4 --spp 16 --json out/c.json"
case_ "overflow info on a constant 3e38 map" error 60 "$cli info $work/huge.pfm"
case_ "overflow precompute a constant 3e38 map" error 60 "$cli precompute $work/huge.pfm -o out/t.envmis"

# outputs: an output that is an input (itself, through a symbolic or a hard link), two
# outputs in one file, library summaries over a map's output or an input. Each must fail
# and leave the input byte-identical.
links='ln -s in.exr in.sym.exr && ln in.exr in.hard.exr && { cp '"$work"'/r.json in.r.json || echo {} >in.r.json; } &&
  ln -s in.r.json in.sym.json && ln in.r.json in.hard.json'
for via in "in.exr:itself" "in.sym.exr:symlink" "in.hard.exr:hard link"; do
  f=${via%%:*} how=${via#*:} j=${f/.exr/.json}
  [[ $f == in.exr ]] && j=in.r.json
  pre=$links case_ "outputs precompute -o the input ($how)" error 60 "$cli precompute in.exr -o $f"
  pre=$links case_ "outputs convert -o the input ($how)" error 60 "$cli convert in.exr -o $f"
  pre=$links case_ "outputs visualize -o the input ($how)" error 60 "$cli visualize in.exr -o $f"
  pre=$links case_ "outputs sample -o the input ($how)" error 60 "$cli sample in.exr -n 16 -o $f"
  pre=$links case_ "outputs compare --json the input ($how)" error 60 "$cli compare in.exr --points 2 --spp 4 --json $f"
  pre=$links case_ "outputs compare --csv the input ($how)" error 60 "$cli compare in.exr --points 2 --spp 4 --csv $f"
  pre=$links case_ "outputs report -o the input ($how)" error 60 "$cli report in.r.json -o $j"
done
case_ "outputs compare --json F --csv F" error 60 "$cli compare in.exr --points 2 --spp 4 --json out/c --csv out/c"
case_ "outputs compare --csv a symlink to --json's file" error 60 "ln -s c out/in.c; $cli compare in.exr --points 2 --spp 4 --json out/c --csv out/in.c"
lib="mkdir in.lib && cp $maps/studio.exr in.lib/a.exr && cp $maps/studio.exr in.lib/summary.exr"
pre=$lib case_ "outputs compare DIR --out-dir: map summary.exr vs summary.json" error 60 "$cli compare in.lib --out-dir out --points 2 --spp 4"
pre=$lib case_ "outputs compare DIR --out-dir --summary onto an input" error 60 "$cli compare in.lib --out-dir out --summary in.lib/a.exr --points 2 --spp 4"
pre="$lib && cp in.exr in.lib/b.exr && $cli precompute in.exr -o in.lib/b.envmis" \
  case_ "outputs compare DIR: b.exr and b.envmis both -> b.json" error 60 "$cli compare in.lib --out-dir out --points 2 --spp 4"
pre=$lib case_ "outputs precompute DIR: --summary = summary.exr's table" error 60 "$cli precompute in.lib -o out --summary out/summary.envmis"
pre=$lib case_ "outputs precompute DIR --summary onto an input" error 60 "$cli precompute in.lib -o out --summary in.lib/a.exr"
pre=$lib case_ "outputs precompute DIR: --summary = a.exr's table" error 60 "$cli precompute in.lib -o out --summary out/a.envmis"

# values: empty, non-finite, negative and absurd option values, and flags that exclude
# each other. Each must fail before doing any work.
c="$cli compare in.exr --spp 4"
case_ "values sample -o ''" error 60 "$cli sample in.exr -n 4 -o ''"
case_ "values compare --json ''" error 60 "$c --points 2 --json ''"
case_ "values compare --csv ''" error 60 "$c --points 2 --csv ''"
case_ "values compare --plots ''" error 60 "$c --points 2 --plots ''"
case_ "values visualize -o ''" error 60 "$cli visualize in.exr -o ''"
case_ "values precompute -o ''" error 60 "$cli precompute in.exr -o ''"
case_ "values compare --normal inf,0,0" error 60 "$c --normal inf,0,0"
case_ "values compare --normal 1e39,0,0" error 60 "$c --normal 1e39,0,0"
case_ "values compare --normal nan,0,0" error 60 "$c --normal nan,0,0"
case_ "values compare --normal 0,0,0" error 60 "$c --normal 0,0,0"
case_ "values compare --normal 0,0,1 --view inf,0,0" error 60 "$c --normal 0,0,1 --view inf,0,0"
case_ "values compare --view without --normal" error 60 "$c --points 2 --view 0,0,1"
case_ "values compare --normal with --points" error 60 "$c --normal 0,0,1 --points 4"
case_ "values compare --bsdf ''" error 60 "$c --points 2 --bsdf ''"
case_ "values compare --bsdf phong:-3" error 60 "$c --points 2 --bsdf phong:-3"
case_ "values compare --bins 0" error 60 "$c --points 2 --bins 0"
case_ "values compare --spp -1" error 60 "$cli compare in.exr --points 2 --spp -1"
case_ "values compare --spp 0" error 60 "$cli compare in.exr --points 2 --spp 0"
case_ "values compare --points 0" error 60 "$c --points 0"
case_ "values compare --points -3" error 60 "$c --points -3"
case_ "values compare --threads 0" error 60 "$c --points 2 --threads 0"
case_ "values compare --env-samples -1" error 60 "$c --points 2 --env-samples -1"
case_ "values compare --view-angle 90" error 60 "$c --points 2 --view-angle 90"
case_ "values compare --alpha -1" error 60 "$c --points 2 --alpha -1"
case_ "values compare --alpha nan" error 60 "$c --points 2 --alpha nan"
case_ "values compare --no-compensate --alpha 0.5" error 60 "$c --points 2 --no-compensate --alpha 0.5"
case_ "values sample --no-compensate --alpha 0.5" error 60 "$cli sample in.exr -n 4 --no-compensate --alpha 0.5"
case_ "values precompute --no-compensate --alpha 0.5" error 60 "$cli precompute in.exr --no-compensate --alpha 0.5 -o out/t.envmis"
case_ "values sample -n -5" error 60 "$cli sample in.exr -n -5"
case_ "values sample -n 0" error 60 "$cli sample in.exr -n 0"
case_ "values sample --normal inf,0,0" error 60 "$cli sample in.exr -n 4 --normal inf,0,0"
case_ "values visualize --panel-width 0" error 60 "$cli visualize in.exr -o out/v.png --panel-width 0"
case_ "values precompute --bins -4" error 60 "$cli precompute in.exr --bins -4 -o out/t.envmis"
case_ "values convert --size 0x0" error 60 "$cli convert in.exr --size 0x0 -o out/c.exr"

# tables: corrupted tables (truncated, a flipped payload byte, a foreign file with only the
# magic) and crafted ones, whose checksums were recomputed after a change (a huge
# threshold, a huge luma coefficient, an all-zero density, radiance of FLT_MAX in one texel
# and in all): info, sample and compare must each fail cleanly, naming the table.
for t in truncated flipped magic-only crafted-threshold crafted-luma crafted-zero-density crafted-fltmax-texel \
  crafted-fltmax-all; do
  f=$work/tables/$t.envmis
  check="grep -qF $t.envmis in.err" bad=unnamed case_ "tables info: $t" error 30 "[ -f $f ] || exit 77; $cli info $f"
  check="grep -qF $t.envmis in.err" bad=unnamed case_ "tables sample: $t" error 30 "[ -f $f ] || exit 77; $cli sample $f -n 64"
  check="grep -qF $t.envmis in.err" bad=unnamed case_ "tables compare: $t" error 60 "[ -f $f ] || exit 77; $cli compare $f --points 4 --spp 16"
done

# special-in: an input that is a FIFO without a writer, or /dev/zero (directly, or through
# a symbolic link named as an image or a table): a clean error within 20 s, no hang.
for kind in fifo zero; do
  if [[ $kind == fifo ]]; then p='mkfifo in.fifo.exr && mkfifo in.fifo.envmis' f=in.fifo.exr t=in.fifo.envmis
  else p='ln -s /dev/zero in.zero.exr && ln -s /dev/zero in.zero.envmis' f=in.zero.exr t=in.zero.envmis
  fi
  pre=$p case_ "special-in info $f" error 20 "$cli info $f"
  pre=$p case_ "special-in info $t" error 20 "$cli info $t"
  pre=$p case_ "special-in precompute $f" error 20 "$cli precompute $f -o out/t.envmis"
  pre=$p case_ "special-in sample $f" error 20 "$cli sample $f -n 4"
  pre=$p case_ "special-in sample $t" error 20 "$cli sample $t -n 4"
  pre=$p case_ "special-in compare $f" error 20 "$cli compare $f --points 2 --spp 4"
done
case_ "special-in info /dev/zero" error 20 "$cli info /dev/zero"
case_ "special-in precompute /dev/zero" error 20 "$cli precompute /dev/zero -o out/t.envmis"
case_ "special-in sample /dev/zero" error 20 "$cli sample /dev/zero -n 4"
case_ "special-in compare /dev/zero" error 20 "$cli compare /dev/zero --points 2 --spp 4"

# sizes: headers that declare 30000x30000 (Radiance .hdr) and 40000x40000 (PFM) pixels
# and hold none, under an 8 GiB address-space limit: a clean error naming the file.
for f in huge-header.hdr huge-header.pfm; do
  for cmd in "info $work/$f" "precompute $work/$f -o out/t.envmis" "compare $work/$f --points 2 --spp 4"; do
    check="grep -qF $f in.err" bad=unnamed case_ "sizes ${cmd%% *} $f (header only), 8 GiB" error 60 \
      "ulimit -v 8388608; $cli $cmd"
  done
done

# stop: compare --exact on the 8192x4096 map, signalled in its set-up (loading, building:
# at 1 s and 3 s) and in its study (0.5 s and 3 s after its progress starts; the set-up
# takes about 5 to 12 s on 2 cores): it must stop within 2 s.
wait_s=10 signal_case "stop compare --exact 8k map set-up, SIGINT at 1 s" INT 1 compare in.big.exr --exact --json out/c.json
wait_s=10 signal_case "stop compare --exact 8k map, SIGTERM at 3 s" TERM 3 compare in.big.exr --exact --json out/c.json
after='compare +0%' wait_s=10 signal_case "stop compare --exact 8k map, SIGTERM 0.5 s into the study" TERM 0.5 \
  compare in.big.exr --exact --json out/c.json
after='compare +0%' wait_s=10 signal_case "stop compare --exact 8k map, SIGTERM 3 s into the study" TERM 3 \
  compare in.big.exr --exact --json out/c.json

# stale: a library precompute of two maps, then one replaced by garbage and the folder
# precomputed again: the failing map's old table must not stay as if valid (it is removed,
# or the run says it is stale).
pre="mkdir in.lib && cp $maps/studio.exr in.lib/a.exr && cp $maps/city.exr in.lib/b.exr && $cli precompute in.lib -o out \
  && [ -f out/b.envmis ] && printf 'garbage, not an image\n' > in.lib/b.exr" \
  check="[ ! -e out/b.envmis ] || grep 'b\.envmis' in.err | grep -qiE 'stale|old|earlier|previous|kept|remov|out of date'" \
  bad=stale case_ "stale precompute DIR, a map turned garbage" error 60 "$cli precompute in.lib -o out"

# names: a file name with ESC and BEL (an xterm title escape): standard error must not
# carry the raw bytes, whether the file is an image, garbage or missing.
pre='cp in.exr "$EVIL"' case_ "names info on an image named with ESC/BEL" ok 60 "$cli info \"\$EVIL\""
pre='cp in.exr "$EVIL"' case_ "names precompute an image named with ESC/BEL" ok 60 "$cli precompute \"\$EVIL\" -o out/t.envmis"
case_ "names info on a missing file named with ESC/BEL" error 60 "$cli info \"\$EVIL\""
case_ "names precompute a missing file named with ESC/BEL" error 60 "$cli precompute \"\$EVIL\" -o out/t.envmis"
pre='echo garbage > "$EVIL"' case_ "names info on garbage named with ESC/BEL" error 60 "$cli info \"\$EVIL\""
pre='echo garbage > "$EVIL"' case_ "names precompute garbage named with ESC/BEL" error 60 "$cli precompute \"\$EVIL\" -o out/t.envmis"
case_ "names precompute -o a name with ESC/BEL in a missing folder" error 60 "$cli precompute in.exr -o \"out/no/such/\$EVIL\""
pre='mkdir in.lib && echo garbage > "in.lib/$EVIL"' \
  case_ "names precompute DIR holding garbage named with ESC/BEL" error 60 "$cli precompute in.lib -o out --summary in.summary.json"

# The classes: cases and verdicts of each; then the failing cases.
echo
printf '%-12s %5s' class cases
for v in "${verdicts[@]}"; do printf ' %*s' $((${#v} > 5 ? ${#v} : 5)) "$v"; done
echo
total=0
for k in "${classes[@]}"; do
  printf '%-12s %5s' "$k" "${cases_of[$k]}"
  for v in "${verdicts[@]}"; do printf ' %*s' $((${#v} > 5 ? ${#v} : 5)) "${count[$k/$v]:-.}"; done
  echo
  total=$((total + cases_of[$k]))
done
echo
echo "$total cases, ${#bad_rows[@]} failing, $((SECONDS - started)) s"
if ((${#bad_rows[@]})); then
  echo "failing cases (case | verdict | first line of standard error):"
  printf '  %s\n' "${bad_rows[@]}"
  exit 1
fi
exit 0
