# Sourced by piglit_compare.sh and capture_corpus.sh, which run the capture layer from a copy taken
# at their start (a rebuild while they run must not mix two versions of the layer).
# copy_package_libraries FIRST_DIR DEST FILE...: copies into DEST every libviper_*.so the FILEs
# load, found in FIRST_DIR first (a copy an earlier run made), else where their RUNPATH points
# (the build's devel/lib).
copy_package_libraries() {
  local first=$1 dest lib
  dest=$(cd "$2" && pwd) || return 1
  shift 2
  for lib in $(LD_LIBRARY_PATH="$first${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" ldd "$@" 2> /dev/null |
    awk '$1 ~ /^libviper_/ && $3 ~ /^\// {print $3}' | sort -u); do
    [ "$(cd "$(dirname "$lib")" && pwd)" = "$dest" ] || cp "$lib" "$dest/" || return 1
  done
}
