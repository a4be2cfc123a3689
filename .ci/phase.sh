# shellcheck shell=bash
# Sourced by scripts/test and scripts/hardening.
# phase NAME COMMAND...: runs COMMAND, then prints "ci: NAME SECONDS s" (whether it passed or not),
# so that a CI log says where its time went, and appends that line to $CI_PHASES when set
# (.ci/run prints them all at the end); returns COMMAND's status.
phase() {
  local name=$1 t0=$SECONDS status=0
  shift
  "$@" || status=$?
  local line="ci: $name $((SECONDS - t0)) s"
  [ "$status" -eq 0 ] || line+=" (failed, status $status)"
  echo "$line"
  if [ -n "${CI_PHASES:-}" ]; then echo "$line" >> "$CI_PHASES"; fi
  return "$status"
}
