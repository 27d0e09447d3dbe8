#!/usr/bin/env bash
# Transparency of the capture layer, measured by Mesa's conformance suite piglit (Debian's package
# `piglit`): runs a slice of piglit's quick_gl and quick_shader profiles twice, plainly and with
# every test program under `capture`, on llvmpipe under Xvfb (GLX, and EGL on X11 for the EGL and
# GLES tests: piglit's mixed_glx_egl platform), compares the results subtest by subtest and prints
# every test whose result differs (plain result -> result under the layer). The goal is none.
#
# Usage: scripts/piglit_compare.sh [--slice ci|full] [--out DIR] [-t REGEX]... [-x REGEX]...
#          [--jobs N] [--timeout S] [--bin DIR] [--keep-going]
#   --slice ci    (default) a few minutes: the areas the layer is known to touch (see ci_include)
#   --slice full  every core GL version's spec tests, ARB/EXT framebuffer objects, buffer objects,
#                 uniform buffers, texture formats, GLSL 1.10-4.50 execution tests (see full_include)
#   -t REGEX      run only tests matching REGEX (piglit's -t, case-insensitive search; repeatable);
#                 given, it replaces the slice's own list, the slice's exclusions still apply
#   -x REGEX      exclude tests matching REGEX too (repeatable)
#   --out DIR     results (DIR/plain, DIR/layer: piglit's own results; DIR/differences.txt: every
#                 differing test with both runs' command, exit status and output); default
#                 build/piglit_compare. Captures are written to DIR/captures and deleted per process.
#   --jobs N      piglit's concurrency (default: the number of CPUs)
#   --timeout S   piglit's per-test time limit, the same in both runs (default 300)
#   --bin DIR     where `capture` is (default: the sourced workspace's, else devel/lib/viper)
# Prints one line per differing result and a summary line; exits 0 when nothing differs, 1 when
# something does, 2 when the runs could not be made.
#
# How the layer run is made: piglit finds its programs in $PIGLIT_BUILD_DIR/bin; the script points
# that at DIR/wrap, whose bin/ has, for each of piglit's programs, a link to
# scripts/piglit_capture_wrapper.sh, which runs the real program through `capture --output
# DIR/captures/NAME.PID.vcap --` (the layer preloaded and capturing, as for any user) and deletes
# the capture. Test names, arguments and data files are piglit's own. DIR/captures/processes.tsv
# lists every process run under capture (name, exit status, capture size): the summary says how
# many there were and how many wrote a capture.
set -uo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
# shellcheck source=layer_copies.sh
source "$here/scripts/layer_copies.sh"
# shellcheck source=package_binaries.sh
source "$here/scripts/package_binaries.sh"

# Areas the layer is known to touch, kept to a few minutes on a 2-core machine (both runs):
# the default framebuffer (front/back reads, draw buffer modes, swap behaviour, the default
# framebuffer's attachment queries), EXT framebuffer objects (the EXT entry points), fixed function
# (OpenGL 1.0's tests, two-sided lighting, line stipple), texture formats with GL_ALPHA, LUMINANCE
# and INTENSITY uploads, shader source errors, the accumulation buffer, and a few GLSL 1.10 fragment
# shaders (the layer rewrites fragment shaders).
ci_include=(
  '^spec@!opengl 1\.0@'
  '^spec@!opengl 1\.1@(clear-accum|linestipple|read-front|teximage-colors gl_(alpha|luminance|intensity)|getteximage-luminance|draw-pixels|copyteximage 2d|masked-clear)'
  '^spec@!opengl 2\.0@(shadersource-errors|vertex-program-two-side)'
  '^spec@ext_framebuffer_object@'
  '^spec@arb_framebuffer_object@(arb_framebuffer_object-get-attachment-parameter-default-framebuffer|fbo-luminance-alpha|fbo-scissor-blit window)'
  '^spec@glsl-1\.10@execution@(fs-|glsl-fs-)'
  '^spec@arb_separate_shader_objects@execution@vs-gs-linking$'
  '^spec@glsl-1\.50@execution@geometry@clip-distance-vs-gs-out-sso$'
)
ci_exclude=(
  '@gl-1\.0-blend-func$'  # 30 s alone (every blend factor pair); runs in the full slice
  ' samples=(6|8|16|32)'   # multisample variants beyond 4 samples: run in the full slice
)
full_include=(
  '^spec@!opengl '                 # every core GL version (1.0 to 4.5, ES 2.0 and 3.0)
  '^spec@arb_framebuffer_object@'
  '^spec@ext_framebuffer_object@'
  '^spec@ext_framebuffer_blit@'
  '^spec@ext_packed_depth_stencil@'
  '^spec@arb_vertex_buffer_object@'  # buffer objects
  '^spec@arb_pixel_buffer_object@'
  '^spec@arb_copy_buffer@'
  '^spec@arb_map_buffer_range@'
  '^spec@arb_buffer_storage@'
  '^spec@arb_clear_buffer_object@'
  '^spec@arb_uniform_buffer_object@'  # uniform buffers
  '^spec@arb_separate_shader_objects@'  # separable programs and pipelines
  '^spec@arb_texture_rg@'          # texture formats
  '^spec@arb_texture_float@'
  '^spec@ext_texture_integer@'
  '^spec@ext_texture_snorm@'
  '^spec@ext_texture_srgb@'
  '^spec@arb_depth_texture@'
  '^spec@arb_depth_buffer_float@'
  '^spec@ext_packed_float@'
  '^spec@ext_texture_shared_exponent@'
  '^spec@arb_texture_rgb10_a2ui@'
  '^spec@arb_texture_compression@'
  '^spec@ext_texture_compression_rgtc@'
  '^spec@ext_texture_compression_s3tc@'
  '^spec@glsl-(1\.[1-5]0|3\.30|4\.[0-5]0)@execution@'  # GLSL 1.10-4.50 execution tests
)
full_exclude=(
  # The generated built-in function, vertex input, conversion, in/out and variable indexing tests
  # of GLSL execution (about 10,000 of its 12,000 shader_runner tests, one process each).
  '^spec@glsl-[0-9.]+@execution@(built-in-functions|vs_in|conversion|inout|variable-indexing)@'
  # Three resource-stress tests, 2 to 4 minutes each alone on llvmpipe (a texture streamed 10,000
  # times, the largest 2D and 3D textures): run them with -t.
  '^spec@!opengl 1\.1@(streaming-texture-leak|max-texture-size)$'
  '^spec@!opengl 1\.2@tex3d-maxsize$'
)

slice=ci; out="$here/build/piglit_compare"; bin=""
jobs=$(nproc); timeout=300
user_include=(); user_exclude=()
# shellcheck source=options.sh
source "$here/scripts/options.sh"
viper_options '2,31' "piglit_compare: unknown option '{}' (see --help)" --slice=slice --out=out \
  -t=user_include+ -x=user_exclude+ --jobs=jobs --timeout=timeout --bin=bin -- "$@"
case "$slice" in
  ci) include=("${ci_include[@]}"); exclude=("${ci_exclude[@]}") ;;
  full)
    include=("${full_include[@]}"); exclude=("${full_exclude[@]}") ;;
  *) echo "piglit_compare: --slice must be ci or full" >&2; exit 2 ;;
esac
[ ${#user_include[@]} -gt 0 ] && include=("${user_include[@]}")
exclude+=("${user_exclude[@]}")

command -v piglit > /dev/null || { echo "piglit_compare: piglit not found: run 'bash scripts/setup.sh --test-programs'" >&2; exit 2; }
command -v Xvfb > /dev/null || { echo "piglit_compare: Xvfb not found (package xvfb)" >&2; exit 2; }
command -v wflinfo > /dev/null || { echo "piglit_compare: wflinfo not found (package waffle-utils; without it piglit skips every shader test)" >&2; exit 2; }
viper_bin_dir piglit_compare "$bin" capture
# The layer run uses a copy of `capture` and the layer taken now, so that a rebuild while it runs
# does not mix two versions of the layer in one run (LD_LIBRARY_PATH finds the copy's
# libviper_*.so, which the layer and capture need, before their build's RUNPATH).
bin=$(cd "$bin" && pwd)
layer_lib=""
for candidate in "$bin/libviper_intercept.so" "$bin/../libviper_intercept.so"; do
  [ -f "$candidate" ] && { layer_lib="$candidate"; break; }
done
[ -n "$layer_lib" ] || { echo "piglit_compare: no libviper_intercept.so beside $bin/capture" >&2; exit 2; }
piglit_root=$("$py" -c 'import os,sys; p=os.path.realpath("/usr/bin/piglit"); print(os.path.dirname(p))' 2> /dev/null)
for candidate in "$piglit_root" /usr/lib/x86_64-linux-gnu/piglit /usr/lib/piglit; do
  [ -d "$candidate/bin" ] && [ -d "$candidate/tests" ] && { piglit_root="$candidate"; break; }
done
[ -d "$piglit_root/bin" ] || { echo "piglit_compare: piglit's programs not found" >&2; exit 2; }

mkdir -p "$out"
out=$(cd "$out" && pwd)
rm -rf "$out/plain" "$out/layer" "$out/wrap" "$out/captures" "$out/bin" "$out/differences.txt"
mkdir -p "$out/wrap/bin" "$out/captures" "$out/bin"
cp "$bin/capture" "$layer_lib" "$out/bin/" || exit 2
# The package's libraries they load (libviper_capture_core.so, and the ground truth `capture`
# reports its verdict with): those beside the layer when there are (a copy made by an earlier run,
# given with --bin), else those their RUNPATH finds: the build's.
copy_package_libraries "$(dirname "$layer_lib")" "$out/bin" "$bin/capture" "$layer_lib" || exit 2
# The layer's behaviour lives in both (the shader rewrite is in libviper_capture_core.so).
layer_id="$(sha1sum "$layer_lib" | cut -c1-12), libviper_capture_core.so $(sha1sum "$out/bin/libviper_capture_core.so" 2> /dev/null | cut -c1-12), built $(date -u -r "$layer_lib" '+%F %T') UTC"
# The layer run's PIGLIT_BUILD_DIR: piglit's tests and generated tests as they are, its programs
# behind the wrapper.
ln -s "$piglit_root/tests" "$out/wrap/tests"
ln -s "$piglit_root/generated_tests" "$out/wrap/generated_tests"
"$py" -c 'import os, sys
for name in os.listdir(sys.argv[1]):
    os.symlink(sys.argv[2], os.path.join(sys.argv[3], name))' "$piglit_root/bin" "$here/scripts/piglit_capture_wrapper.sh" "$out/wrap/bin"

filters=()
for f in "${include[@]}"; do filters+=(-t "$f"); done
for f in "${exclude[@]}"; do filters+=(-x "$f"); done

# Both runs alike: llvmpipe, a fresh Xvfb of their own (its display number chosen by Xvfb itself,
# ready when it says so: no race with another Xvfb on the machine), the same tests, concurrency and
# time limit; nothing of the layer's in the plain run's environment.
xvfb_pid=""
stop_xvfb() { [ -n "$xvfb_pid" ] && kill "$xvfb_pid" 2> /dev/null && wait "$xvfb_pid" 2> /dev/null; xvfb_pid=""; }
trap stop_xvfb EXIT
start_xvfb() {  # name
  local number="$out/xvfb.$1.display"
  : > "$number"
  # -noreset: an X server resets when its last client leaves, and a test connecting meanwhile fails
  # with "XOpenDisplay failed" (26 of 3,140 tests, in one run or the other, in a first full run).
  Xvfb -displayfd 3 -screen 0 1280x1024x24 -nolisten tcp -noreset 3> "$number" > "$out/xvfb.$1.log" 2>&1 &
  xvfb_pid=$!
  for _ in $(seq 300); do
    [ -s "$number" ] && break
    kill -0 "$xvfb_pid" 2> /dev/null || break
    sleep 0.1
  done
  [ -s "$number" ] || { echo "piglit_compare: Xvfb did not start (log $out/xvfb.$1.log)" >&2; return 1; }
  display=":$(head -1 "$number")"
}
run_piglit() {  # name, then extra environment (NAME=VALUE...)
  local name="$1"; shift
  local start=$SECONDS display
  start_xvfb "$name" || return 1
  env -u LD_PRELOAD -u VIPER_CAPTURE_OUTPUT -u VIPER_CAPTURE_PROFILE -u VIPER_CAPTURE_STATUS_FD -u WAYLAND_DISPLAY \
    DISPLAY="$display" LIBGL_ALWAYS_SOFTWARE=1 GALLIUM_DRIVER=llvmpipe "$@" \
    piglit run -p mixed_glx_egl -j "$jobs" --timeout "$timeout" -l dummy -o "${filters[@]}" \
    quick_gl quick_shader "$out/$name" > "$out/$name.log" 2>&1
  local rc=$?
  stop_xvfb
  echo "piglit_compare: $name run: $((SECONDS - start)) s (piglit exit $rc; log $out/$name.log)"
  [ -f "$out/$name/results.json.bz2" ] || [ -f "$out/$name/results.json" ] || {
    echo "piglit_compare: the $name run wrote no results:" >&2; tail -20 "$out/$name.log" >&2; return 1; }
}

echo "piglit_compare: slice $slice; include: ${include[*]}; exclude: ${exclude[*]:-(none)}; jobs $jobs"
run_piglit plain || exit 2
echo "piglit_compare: layer $layer_lib (copied: sha1 $layer_id)"
run_piglit layer PIGLIT_BUILD_DIR="$out/wrap" VIPER_PIGLIT_CAPTURE="$out/bin/capture" \
  VIPER_INTERCEPT_LIBRARY="$out/bin/libviper_intercept.so" LD_LIBRARY_PATH="$out/bin${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" \
  VIPER_PIGLIT_REAL_BIN="$piglit_root/bin" VIPER_PIGLIT_CAPTURE_DIR="$out/captures" || exit 2
rm -f "$out"/captures/*.vcap  # any left by a process killed with the wrapper (a time limit)

"$py" - "$out" <<'PY'
import bz2, json, os, sys

out = sys.argv[1]

def load(name):
    path = os.path.join(out, name, "results.json.bz2")
    data = json.load(bz2.open(path)) if os.path.exists(path) else json.load(open(path[:-4]))
    return data["tests"]

plain, layer = load("plain"), load("layer")
MISSING = "missing"
# Worse means further down this list.
RANK = {"pass": 0, "skip": 1, "notrun": 1, "warn": 2, "dmesg-warn": 2, "fail": 3, "dmesg-fail": 3,
        "timeout": 4, "crash": 5, "incomplete": 5, MISSING: 5}

def units(test):
    """The results compared: each subtest of a test that has them, else the test itself."""
    subs = {k: v for k, v in (test or {}).get("subtests", {}).items() if k != "__type__"}
    return subs

counts = {"plain": {}, "layer": {}}
diffs = []  # (test, subtest or None, plain result, layer result, counted as a compared result)
compared = 0
for name in sorted(set(plain) | set(layer)):
    p, l = plain.get(name), layer.get(name)
    ps, ls = units(p), units(l)
    if ps or ls:
        for sub in sorted(set(ps) | set(ls)):
            a, b = ps.get(sub, MISSING), ls.get(sub, MISSING)
            compared += 1
            counts["plain"][a] = counts["plain"].get(a, 0) + 1
            counts["layer"][b] = counts["layer"].get(b, 0) + 1
            if a != b:
                diffs.append((name, sub, a, b, True))
    a = p["result"] if p else MISSING
    b = l["result"] if l else MISSING
    if not (ps or ls):
        compared += 1
        counts["plain"][a] = counts["plain"].get(a, 0) + 1
        counts["layer"][b] = counts["layer"].get(b, 0) + 1
    if a != b:
        diffs.append((name, None, a, b, not (ps or ls)))

tests = sorted({d[0] for d in diffs})
with open(os.path.join(out, "differences.txt"), "w") as f:
    for name in tests:
        f.write("=" * 100 + "\n" + name + "\n")
        for d in diffs:
            if d[0] == name:
                f.write("  %s: %s -> %s\n" % ("subtest '%s'" % d[1] if d[1] else "result", d[2], d[3]))
        for run, results in (("plain", plain), ("layer", layer)):
            t = results.get(name)
            if not t:
                f.write("--- %s: not run\n" % run)
                continue
            f.write("--- %s: %s, exit %s, %.2f s\n" % (run, t.get("command"), t.get("returncode"),
                                                     t["time"]["end"] - t["time"]["start"]))
            for stream in ("out", "err"):
                text = (t.get(stream) or "").strip()
                if text:
                    f.write("  [%s]\n" % stream + "".join("    " + line + "\n" for line in text.splitlines()[-60:]))

for name, sub, a, b, _ in diffs:
    print("DIFF %s%s: %s -> %s" % (name, " (subtest '%s')" % sub if sub else "", a, b))
counted = [d for d in diffs if d[4]]
worse = sum(1 for d in counted if RANK.get(d[3], 5) > RANK.get(d[2], 5))
fmt = lambda c: ", ".join("%s %d" % (k, v) for k, v in sorted(c.items(), key=lambda kv: (RANK.get(kv[0], 9), kv[0])))
print("piglit_compare: plain: %s" % fmt(counts["plain"]))
print("piglit_compare: layer: %s" % fmt(counts["layer"]))
procs = os.path.join(out, "captures", "processes.tsv")
rows = [line.rstrip("\n").split("\t") for line in open(procs)] if os.path.exists(procs) else []
captured = sum(1 for r in rows if len(r) == 3 and r[2] not in ("-", "0"))
started = sum(1 for t in layer.values() if t.get("returncode") is not None)
print("piglit_compare: layer run: %d tests ran a program, %d test processes under capture, %d of them wrote a capture "
      "stream (the others made no call the layer records, e.g. skipped before making a context)" %
      (started, len(rows), captured))
print("piglit_compare: %d tests, %d results compared: %d differ in %d tests (%d worse under the layer)%s" %
      (len(set(plain) | set(layer)), compared, len(counted), len(tests), worse,
       "; details: " + os.path.join(out, "differences.txt") if diffs else ""))
if len(rows) < started:
    print("piglit_compare: fewer processes ran under capture than tests ran: the layer run is not what it claims",
          file=sys.stderr)
    sys.exit(2)
sys.exit(1 if diffs else 0)
PY
