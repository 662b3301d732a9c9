#!/usr/bin/env bash
# The fault matrix of issue 18: runs `envmis` as a user would against full disks,
# signals, killed runs, special files, absurd sizes, unwritable standard output and
# overflowing maps, and prints one row per case: what was tried, the exit code, the
# seconds it took, what it left in its output folder, and a verdict:
#   clean error    non-zero exit (a one-line message), nothing left at the destination
#   clean stop     a signalled run exited 130/143 within 2 s and left nothing unmarked
#   wrong success  exit 0 where the run could not have succeeded
#   crash          killed by a signal it did not handle (or sanitizer/abort)
#   hang / slow    ran past its time limit / a signal took more than 2 s to act on
#   leftovers      the run left a partial or temporary file behind
# Usage: scripts/faults.sh [path/to/envmis]   (default build/apps/envmis)
#        FAULTS_ONLY=REGEX scripts/faults.sh ...  runs only the cases whose names match
# Every output is bounded: file sizes by `ulimit -f`, runs by `timeout`.
set -uo pipefail
cd "$(dirname "$0")/.."
cli=$(realpath "${1:-build/apps/envmis}")
export OCIO=${OCIO:-$PWD/data/ocio/config.ocio}
maps=$PWD/data/envmaps
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

printf '%-58s %5s %6s  %-14s %s\n' case exit secs verdict leftovers
row() { printf '%-58s %5s %6s  %-14s %s\n' "$1" "$2" "$3" "$4" "$5"; }

# The files a case left in its folder, besides its inputs (named in.*).
leftovers() { (cd "$1" && find . -mindepth 1 ! -type d ! -name 'in.*' -printf '%P ' | head -c 200); }

# Runs one case in a fresh folder: expect "error" (must fail cleanly) or "ok" (must exit 0
# and leave no temporary). Files named in.* are the case's own inputs and not counted; a
# command exits 77 when the machine cannot set the case up (mknod without privilege).
# Arguments: name, expect, limit in seconds, then a shell command run in the folder.
case_() {
  [[ $1 =~ ${FAULTS_ONLY:-.} ]] || return 0
  local name=$1 expect=$2 limit=$3 dir=$work/$RANDOM$RANDOM
  shift 3
  mkdir -p "$dir/out" && cp "$maps/studio.exr" "$dir/in.exr"
  local start=$SECONDS rc
  (cd "$dir" && timeout -s KILL "$limit" bash -c "$*" >/dev/null 2>"$dir/in.err") 2>/dev/null
  rc=$?
  local secs=$((SECONDS - start)) left verdict
  left=$(leftovers "$dir")
  if ((rc == 137)); then verdict=hang
  elif ((rc == 77)); then verdict=skipped
  elif ((rc >= 128)); then verdict=crash
  elif [[ $expect == error && $rc == 0 ]]; then verdict="wrong success"
  elif [[ $expect == error && -n $left ]]; then verdict=leftovers
  elif [[ $expect == error ]]; then verdict="clean error"
  elif ((rc != 0)); then verdict=failed
  elif [[ $left == *.tmp* ]]; then verdict=leftovers
  else verdict=ok
  fi
  row "$name" "$rc" "$secs" "$verdict" "$left"
}

# A run signalled after `delay` seconds; it must exit 128 + signal within 2 s.
signal_case() {
  [[ $1 =~ ${FAULTS_ONLY:-.} ]] || return 0
  local name=$1 signal=$2 delay=$3 dir=$work/$RANDOM$RANDOM
  shift 3
  mkdir -p "$dir/out" && cp "$maps/studio.exr" "$dir/in.exr"
  [[ -f $work/big.exr ]] && ln -s "$work/big.exr" "$dir/in.big.exr"
  (cd "$dir" && exec "$cli" "$@" >/dev/null 2>"$dir/in.err") 2>/dev/null &
  local pid=$!
  sleep "$delay"
  kill -"$signal" "$pid" 2>/dev/null
  local sent=$SECONDS waited=0
  while kill -0 "$pid" 2>/dev/null && ((waited < 60)); do sleep 0.1; waited=$((SECONDS - sent)); done
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
  row "$name" "$rc" "$secs" "$verdict" "$left"
}

# Inputs made once: an 8192x4096 map (a few seconds to load and precompute), a 1x65536
# map, a constant 3e38 map (PFM: finite floats whose sums overflow).
"$cli" convert "$maps/studio.exr" --from equirect --to equirect --size 8192x4096 -o "$work/big.exr" >/dev/null 2>&1
python3 - "$work" <<'PY'
import struct, sys
def pfm(path, w, h, value):
    with open(path, "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (w, h))
        f.write(struct.pack("<%df" % (3 * w * h), *([value] * (3 * w * h))))
pfm(sys.argv[1] + "/tall.pfm", 1, 65536, 1.0)
pfm(sys.argv[1] + "/huge.pfm", 64, 32, 3e38)
PY

# 1. Full disk (a 100 KB file-size limit; SIGXFSZ is what the kernel sends past it).
case_ "1 visualize -> PNG, disk full" error 120 "ulimit -f 100; $cli visualize in.exr -o out/x.png --panel-width 1024"
case_ "1 compare --plots -> PNGs, disk full" error 300 "ulimit -f 4; $cli compare in.exr --points 4 --spp 16 --plots out"
case_ "1 compare --images -> PNG, disk full" error 300 "ulimit -f 20; $cli compare in.exr --points 4 --spp 16 --images out"
case_ "1 precompute -> table, disk full" error 120 "ulimit -f 100; $cli precompute in.exr -o out/t.envmis"
case_ "1 convert -> EXR, disk full" error 120 "ulimit -f 100; $cli convert in.exr -o out/c.exr"
case_ "1 compare --csv/--json, disk full" error 300 "ulimit -f 1; $cli compare in.exr --points 64 --spp 16 --csv out/c.csv --json out/c.json"

# 2. Signals.
signal_case "2 precompute 8k map, SIGINT at 1 s" INT 1 precompute in.big.exr -o out/t.envmis
signal_case "2 precompute 8k map --bins 121, SIGTERM at 3 s" TERM 3 precompute in.big.exr --bins 121 -o out/t.envmis
signal_case "2 convert --size 16384, SIGINT at 2 s" INT 2 convert in.exr --size 16384 -o out/c.exr
signal_case "2 compare --spp 1e9, SIGINT at 2 s" INT 2 compare in.exr --spp 1000000000 --points 100000 --json out/c.json --csv out/c.csv
signal_case "2 compare --spp 1e9, SIGTERM at 2 s" TERM 2 compare in.exr --spp 1000000000 --points 100000 --json out/c.json
signal_case "2 visualize 8k map, SIGTERM at 1 s" TERM 1 visualize in.big.exr -o out/v.png --panel-width 4096

# 3. Killed runs: a temporary left by a SIGKILL is gone after the next write.
case_ "3 SIGKILL mid-write, then rerun" ok 120 "ln -s $work/big.exr in.big.exr; ($cli precompute in.big.exr -o out/t.envmis & p=\$!;
  for i in \$(seq 600); do ls out/.t* >/dev/null 2>&1 && break; sleep 0.1; done; kill -KILL \$p; wait \$p;
  ls out/.t* >/dev/null 2>&1) || exit 77; $cli precompute in.exr -o out/t.envmis"

# 4. -o onto special files.
case_ "4 -o onto a FIFO" error 30 "mkfifo out/in.f.envmis; $cli precompute in.exr -o out/in.f.envmis"
case_ "4 -o onto a symlink" error 30 "echo keep > in.target; ln -s ../in.target out/in.l.envmis; $cli precompute in.exr -o out/in.l.envmis"
case_ "4 -o onto a character device" error 30 "mknod out/in.null.envmis c 1 3 || exit 77; $cli precompute in.exr -o out/in.null.envmis"
case_ "4 rewrite keeps mode 0600" ok 60 "$cli precompute in.exr -o out/t.envmis && chmod 600 out/t.envmis && $cli precompute in.exr -o out/t.envmis && [ \$(stat -c %a out/t.envmis) = 600 ]"

# 6. Absurd sizes.
case_ "6 visualize a 1x65536 map" error 60 "$cli visualize $work/tall.pfm -o out/v.png"
case_ "6 convert --size 40000" error 60 "$cli convert in.exr --size 40000 -o out/c.exr"
case_ "6 bench --size 65536x65536" error 60 "$cli bench --size 65536x65536"
case_ "6 convert --size -1" error 60 "$cli convert in.exr --size -1 -o out/c.exr"
case_ "6 compare --threads 4000" error 60 "$cli compare in.exr --points 2 --spp 4 --threads 4000"

# 7. Standard output that cannot be written.
case_ "7 info > /dev/full" error 60 "$cli info in.exr > /dev/full"
# The table is complete and stays (named in.* so as not to count): only the report failed.
case_ "7 precompute > /dev/full" error 60 "$cli precompute in.exr -o out/in.t.envmis > /dev/full"
case_ "7 compare > /dev/full" error 120 "$cli compare in.exr --points 4 --spp 16 > /dev/full"

# 8. Overflow: a constant 3e38 map.
case_ "8 compare on a constant 3e38 map" error 120 "$cli compare $work/huge.pfm --points 4 --spp 16 --json out/c.json"
case_ "8 info on a constant 3e38 map" error 60 "$cli info $work/huge.pfm"
case_ "8 precompute a constant 3e38 map" error 60 "$cli precompute $work/huge.pfm -o out/t.envmis"
