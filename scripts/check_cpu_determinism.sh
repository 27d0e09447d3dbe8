#!/usr/bin/env bash
# Whether generate writes the same files on other x86-64 CPUs: the committed test-scene bag
# (bags/test_scene_raw.bag, 20 frames at 640x480) generated twice natively (the same files both
# times, or the script fails) and once under QEMU's user-mode emulation of each CPU model named,
# which makes the package's and its libraries' run-time dispatch (AVX-512, AVX2 + FMA, SSE4.2, ...)
# take that CPU's paths; then, per output, how many files differ from the native run's.
# Needs qemu-user (apt-get install qemu-user; not installed by setup.sh: this is a check, not a test).
# Usage: source devel/setup.bash; scripts/check_cpu_determinism.sh [CPU_MODEL...]
#   (default: Haswell Nehalem; `qemu-x86_64 -cpu help` lists the models; TCG emulates no AVX-512)
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
cpus=("$@")
[ ${#cpus[@]} -gt 0 ] || cpus=(Haswell Nehalem)
command -v qemu-x86_64 > /dev/null || { echo "check_cpu_determinism: needs qemu-x86_64 (apt-get install qemu-user)" >&2; exit 2; }
# shellcheck source=package_binaries.sh
source "$here/scripts/package_binaries.sh"
viper_bin_dir check_cpu_determinism "" generate
work=$(mktemp -d /tmp/viper_cpu_determinism.XXXXXX)
trap 'rm -rf "$work"' EXIT
gen() {  # gen OUT [emulator args...]
  local out=$1; shift
  "$@" "$bin/generate" --input "$here/bags/test_scene_raw.bag" --labels "$here/config/labels/test_scene_labels.yaml" \
    --out "$work/$out" > "$work/$out.log" 2>&1 || { echo "check_cpu_determinism: generate failed ($out): see below" >&2; tail -5 "$work/$out.log" >&2; exit 1; }
  (cd "$work/$out" && find . -type f ! -name '*.done' | sort | xargs sha256sum) > "$work/$out.sha"
}
differing() {  # differing OUT: per output folder, the files whose bytes differ from the native run's
  (cd "$work/$1" && sha256sum -c "$work/native.sha" 2>/dev/null | grep -v ': OK$' | cut -d/ -f3 | sort | uniq -c |
    awk '{printf "%s%s %s", (NR > 1 ? ", " : ""), $1, $2}') || true
}
gen native
gen native2
total=$(wc -l < "$work/native.sha")
same=$(differing native2)
echo "native CPU: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'); $total files a run"
[ -z "$same" ] || { echo "check_cpu_determinism: two native runs differ: $same" >&2; exit 1; }
echo "| CPU | files that differ from the native run's |"
echo "| --- | --- |"
echo "| native, again | none |"
for cpu in "${cpus[@]}"; do
  gen "$cpu" qemu-x86_64 -cpu "$cpu"
  d=$(differing "$cpu")
  echo "| $cpu (QEMU) | ${d:-none} |"
done
