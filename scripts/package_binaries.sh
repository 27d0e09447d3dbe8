# shellcheck shell=bash disable=SC2034  # bin, generate, py: the sourcing script's
# Sourced by every script that runs the package's executables or ROS's tools: the one way they find
# both. Usage: source "$here/scripts/package_binaries.sh", then
#
#   viper_bin_dir WHO DIR NAME...
#       Sets $bin to the folder of the package's executables and checks that each NAME is an
#       executable there. DIR, when not empty, is taken as given (a script's --bin DIR or BIN_DIR
#       argument). Otherwise: the sourced workspace's, as rosrun finds them (catkin_find --libexec
#       viper: the first of its folders that holds every NAME), else, when no sourced workspace holds
#       the package, this checkout's devel/lib/viper. A NAME missing: "WHO: no NAME in DIR (...)"
#       naming where it looked, and exit 2.
#   viper_generate WHO
#       Sets $generate: $VIPER_GENERATE when set (the executable itself: scripts/slurm/submit.sh
#       passes it on to its jobs), else generate in viper_bin_dir's folder; checked the same way.
#   viper_ros_env WHO [DEVEL]
#       The ROS environment for roslaunch, rosrun and the package's launch files: DEVEL/setup.bash
#       sourced when DEVEL is given (a script that runs its own tree: test.sh, sanitize.sh, run.sh);
#       else the sourced workspace when it holds the package, else this checkout's devel/setup.bash.
#       Either way /usr/bin comes first on PATH (py, below). No setup.bash: "WHO: no ... build first", exit 2.
#   py, ros_tool TOOL ARG...
#       Debian's python3, which has the ROS modules (python3-rosbag, ...) and what scripts/setup.sh
#       installs for the scripts (numpy, PIL, yaml), whatever python3 comes first on PATH (a pyenv,
#       a virtualenv); ros_tool runs a ROS Python tool (rosbag, rosnode, rosparam, roslaunch,
#       catkin_find) with it. A tool started in the background whose PID the script keeps runs as
#       "$py" "$(command -v TOOL)" ... & instead (the PID is then the tool's, not a subshell's).
py=/usr/bin/python3
ros_tool() { local tool=$1; shift; "$py" "$(command -v "$tool")" "$@"; }

# This checkout (the folder above scripts/); its devel space is where scripts/setup.sh builds.
viper_checkout=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

# The sourced workspace's folders of the package's executables, one a line (none: no workspace
# that holds the package is sourced).
viper_workspace_bin_dirs() {
  command -v catkin_find > /dev/null || return 0
  ros_tool catkin_find --without-underlays --libexec viper 2> /dev/null || true
}

viper_list() { local IFS=,; echo "$*" | sed 's/,/, /g'; }

viper_bin_dir() {
  local who=$1 dir=$2 name missing where candidates
  shift 2
  if [ -n "$dir" ]; then
    candidates=("$dir") where="the folder given"
  else
    mapfile -t candidates < <(viper_workspace_bin_dirs)
    where="the sourced workspace's, from catkin_find --libexec viper"
    if [ ${#candidates[@]} -eq 0 ]; then
      candidates=("$viper_checkout/devel/lib/viper") where="this checkout's devel space; no sourced workspace holds the package"
    fi
  fi
  for dir in "${candidates[@]}"; do
    missing=()
    for name in "$@"; do [ -x "$dir/$name" ] || missing+=("$name"); done
    [ ${#missing[@]} -eq 0 ] && { bin=$dir; return 0; }
  done
  if [ ${#candidates[@]} -eq 1 ]; then
    echo "$who: no $(viper_list "${missing[@]}") in ${candidates[0]} ($where): build first (scripts/setup.sh)" >&2
  else
    echo "$who: none of $(viper_list "${candidates[@]}") holds $(viper_list "$@") ($where): build first (scripts/setup.sh)" >&2
  fi
  case " ${missing[*]} " in
    *" bench_"*) echo "$who: (the bench_* programs are built only where libbenchmark-dev is installed; scripts/setup.sh installs it)" >&2 ;;
  esac
  exit 2
}

viper_generate() {
  if [ -n "${VIPER_GENERATE:-}" ]; then
    viper_bin_dir "$1" "$(dirname "$VIPER_GENERATE")" "$(basename "$VIPER_GENERATE")"
    generate=$bin/$(basename "$VIPER_GENERATE")
  else
    viper_bin_dir "$1" "" generate
    generate=$bin/generate
  fi
}

viper_ros_env() {
  local who=$1 devel=${2:-} nounset=0
  if [ -z "$devel" ]; then
    [ -n "$(viper_workspace_bin_dirs)" ] || devel="$viper_checkout/devel"
  fi
  # ROS's Python tools and nodes that start with `env python3` (rostest, roslaunch-check, the
  # package's Python nodes) need Debian's, which has the ROS modules.
  export PATH="/usr/bin:$PATH"
  [ -n "$devel" ] || return 0
  [ -f "$devel/setup.bash" ] || { echo "$who: no $devel/setup.bash: build first (scripts/setup.sh)" >&2; exit 2; }
  case $- in *u*) nounset=1 ;; esac
  set +u  # ROS env hooks read unset variables
  set --  # setup.bash passes its arguments on to catkin's _setup_util.py: none
  # shellcheck disable=SC1091
  source "$devel/setup.bash"
  [ "$nounset" -eq 0 ] || set -u
}
