# shellcheck shell=bash
# Sourced by the scripts that take options: viper_options reads a script's arguments into its
# variables, the same way for every script.
#
# Usage: viper_options HELP UNKNOWN SPEC... -- "$@"
#   HELP     the lines of the script's head comment that -h and --help print (sed's range, e.g.
#            '2,12'), then exit 0; '' where the script has no help (-h is then an unknown option)
#   UNKNOWN  what any other argument prints on stderr before exit 2; {} stands for the argument
#   SPEC     --name=VAR    the next argument into $VAR
#            --name=VAR+   the next argument appended to the array VAR
#            --name=VAR:V  $VAR set to V (a flag: no argument)
#            GLOB=         arguments that match GLOB are skipped (e.g. '__*:=*', roslaunch's)
# An option without its argument ends the script as `set -u` does (unbound variable).
viper_options() {
  local _vo_help=$1 _vo_unknown=$2 _vo_spec _vo_skip=() _vo_i
  local -A _vo_value=() _vo_append=() _vo_flag=()
  shift 2
  while [ "$1" != -- ]; do
    _vo_spec=$1
    case "$_vo_spec" in
      *=) _vo_skip+=("${_vo_spec%=}") ;;
      *=*+) _vo_spec=${_vo_spec%+}; _vo_append[${_vo_spec%%=*}]=${_vo_spec#*=} ;;
      *=*:*) _vo_flag[${_vo_spec%%=*}]=${_vo_spec#*=} ;;
      *) _vo_value[${_vo_spec%%=*}]=${_vo_spec#*=} ;;
    esac
    shift
  done
  shift
  while [ $# -gt 0 ]; do
    for _vo_i in "${_vo_skip[@]}"; do
      # shellcheck disable=SC2053  # a glob on purpose
      [[ $1 == $_vo_i ]] && { shift; continue 2; }
    done
    if [ -z "$1" ]; then
      echo "${_vo_unknown//\{\}/}" >&2
      exit 2
    elif [ -n "${_vo_value[$1]:-}" ]; then
      printf -v "${_vo_value[$1]}" '%s' "$2"
      shift 2
    elif [ -n "${_vo_append[$1]:-}" ]; then
      local -n _vo_array=${_vo_append[$1]}
      _vo_array+=("$2")
      unset -n _vo_array
      shift 2
    elif [ -n "${_vo_flag[$1]:-}" ]; then
      printf -v "${_vo_flag[$1]%%:*}" '%s' "${_vo_flag[$1]#*:}"
      shift
    elif [ -n "$_vo_help" ] && { [ "$1" = -h ] || [ "$1" = --help ]; }; then
      sed -n "${_vo_help}p" "$0"
      exit 0
    else
      echo "${_vo_unknown//\{\}/"$1"}" >&2
      exit 2
    fi
  done
}
