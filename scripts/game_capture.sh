# shellcheck shell=bash disable=SC2034  # bin: the sourcing script's
# Sourced by capture_minetest.sh and capture_supertuxkart.sh, which capture a game whose source and
# assets are not ours: the steps they share around the game's run. WHO, the script's name, starts
# their messages. Usage: source "$here/scripts/game_capture.sh", then
#
#   game_capture_setup WHO GAME BIN CHECK BAG
#       Exits 2 unless GAME is an executable (installed by scripts/setup.sh --test-programs), then
#       sets $bin as package_binaries.sh's viper_bin_dir does (BIN: the script's --bin), to a folder
#       with capture, capture_check (unless CHECK is 0) and capture_to_bag (unless BAG is 0).
#   game_capture_result WHO STATUS LOG
#       Prints the capture layer's lines of LOG (the game's output); unless STATUS (the game's exit
#       status) is 0, exits 1 naming it and LOG.
#   game_capture_outputs CAPTURE CHECK BAG RAW_BAG WHAT [CAPTURE_CHECK_ARG...]
#       Unless CHECK is 0, "== checking WHAT" and capture_check CAPTURE CAPTURE_CHECK_ARG...; unless
#       BAG is 0, "== raw bag -> RAW_BAG" and capture_to_bag CAPTURE into RAW_BAG.
# shellcheck source=package_binaries.sh
source "$(dirname "${BASH_SOURCE[0]}")/package_binaries.sh"

game_capture_setup() {
  local who=$1 game=$2 bin_arg=$3 check=$4 bag=$5
  [ -x "$game" ] || { echo "$who: $game not found: run 'bash scripts/setup.sh --test-programs'" >&2; exit 2; }
  viper_bin_dir "$who" "$bin_arg" capture $([ "$check" -eq 0 ] || echo capture_check) \
    $([ "$bag" -eq 0 ] || echo capture_to_bag)
}

game_capture_result() {
  local who=$1 status=$2 log=$3
  grep '\[viper capture\]' "$log" || true
  [ "$status" -eq 0 ] || { echo "$who: the game exited with $status (log: $log)" >&2; exit 1; }
}

game_capture_outputs() {
  local capture=$1 check=$2 bag=$3 raw_bag=$4 what=$5
  shift 5
  if [ "$check" -eq 1 ]; then
    echo "== checking $what"
    "$bin/capture_check" "$capture" "$@"
  fi
  if [ "$bag" -eq 1 ]; then
    echo "== raw bag -> $raw_bag"
    "$bin/capture_to_bag" "$capture" --output "$raw_bag"
  fi
}
