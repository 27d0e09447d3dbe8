#!/usr/bin/env bash
# Installs every dependency of viper from Debian's packages (idempotent, as root) and builds the
# package: CMake's build tree in build/, the catkin devel space in devel/ (outside build/, where
# rosrun would not look for the commands).
# Usage: scripts/setup.sh [--no-build] [--test-programs] [--training]
#   --test-programs: also what only the tests need: the third-party programs they capture
#                    (SuperTuxKart, Minetest), apitrace (records it once, replays it the same every time),
#                    Chromium and Playwright (npm) for the labelling page's browser test, Slurm and
#                    munge for the dataset generator's cluster test (scripts/test_slurm.sh), Mesa's
#                    conformance suite piglit with waffle-utils (wflinfo, without which piglit skips
#                    every shader test) for the layer's transparency test (scripts/piglit_compare.sh),
#                    and the corpus of programs scripts/capture_corpus.sh captures (glmark2-x11,
#                    neverball, supertux, foobillardplus, chromium-bsu, extremetuxracer, mesa-utils).
#                    scripts/test.sh asks for them; a user who only captures their own program does not.
#   --training:      also PyTorch (python3-torch), which only scripts/train_segmentation.py needs: the
#                    segmentation baseline's node and tests run the committed ONNX networks with OpenCV.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)

PKGS=(
  build-essential cmake pkg-config clang
  catkin ros-core-dev libroscpp-dev libtf2-ros-dev libtf2-eigen-dev librosbag-dev
  librostest-dev python3-rostest python3-rosbag python3-roslaunch rosbash
  libcv-bridge-dev libimage-transport-dev libnodeletlib-dev libnodeletlib-tools python3-rostopic python3-rosnode
  libmessage-filters-dev libroslib-dev libtf2-dev libtopic-tools-dev rviz
  ros-sensor-msgs ros-nav-msgs ros-visualization-msgs ros-std-msgs ros-geometry-msgs
  ros-message-generation ros-message-runtime ros-rosgraph-msgs
  libeigen3-dev libopencv-dev libyaml-cpp-dev libzstd-dev libxxhash-dev
  libegl-dev libgl-dev libglx-dev libegl-mesa0 libgl1-mesa-dri libgles-dev
  libgtest-dev libbenchmark-dev
  libcli11-dev
  libvulkan-dev mesa-vulkan-drivers vulkan-tools vulkan-validationlayers spirv-headers spirv-tools glslang-tools
  libxcb1-dev
  xvfb imagemagick
  libzip-dev python3-numpy python3-pil libpng-dev libjpeg-dev libssl-dev libdeflate-dev libisal-dev liblz4-dev libbz2-dev
  libstd-srvs-dev python3-std-srvs libopencv-apps-dev ros-opencv-apps python3-opencv-apps python3-sensor-msgs
  libopencv-dnn-dev python3-yaml
)

build=1
test_programs=0
for arg in "$@"; do
  case "$arg" in
    --no-build) build=0 ;;
    --test-programs) PKGS+=(supertuxkart minetest apitrace chromium nodejs slurm-wlm munge piglit waffle-utils
                            glmark2-x11 neverball supertux foobillardplus chromium-bsu extremetuxracer mesa-utils
                            wine wine64 g++-mingw-w64-x86-64-posix); test_programs=1 ;;
    --training) PKGS+=(python3-torch) ;;
    *) echo "setup: unknown option '$arg' (known: --no-build, --test-programs, --training)" >&2; exit 2 ;;
  esac
done

missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO=sudo
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

if [ "$test_programs" -eq 1 ] && [ ! -d "$here/test/label_page/node_modules/playwright-core" ]; then
  # The labelling page's browser test drives Chromium with Playwright (from the npm registry).
  command -v npm > /dev/null || { echo "setup: npm is missing (the label page test needs node and npm)" >&2; exit 1; }
  (cd "$here/test/label_page" && npm ci --no-audit --no-fund --loglevel=error)
fi

[ "$build" -eq 1 ] || exit 0

mkdir -p "$here/build"
cd "$here/build"
cmake "$here" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 \
  -DCATKIN_DEVEL_PREFIX="$here/devel" >/dev/null
make -j"$(nproc)"
echo "setup: built; run 'source $here/devel/setup.bash' to use rosrun/roslaunch"
