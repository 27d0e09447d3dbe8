# Sourced by scripts/measure_pipeline.sh and measure_evaluate.sh: Debian's python for the ROS tools
# (ros_tool), the sourced workspace's executables ($bin), a work folder ($work) removed on exit
# together with every background process listed in $pids.
# Usage: source "$here/scripts/measure_common.sh" NAME
command -v catkin_find >/dev/null || { echo "$1: source <build>/devel/setup.bash first" >&2; exit 2; }
py=/usr/bin/python3
ros_tool() { local tool=$1; shift; "$py" "$(command -v "$tool")" "$@"; }
bin=$(dirname "$("$py" "$(command -v catkin_find)" --without-underlays --libexec viper | head -1)/x")

work=$(mktemp -d "/tmp/viper_$1.XXXXXX")
pids=()
cleanup() {
  local pid
  for pid in "${pids[@]}"; do kill -INT "$pid" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do wait "$pid" 2>/dev/null || true; done
  rm -rf "$work"
}
trap cleanup EXIT
