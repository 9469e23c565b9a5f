# Sourced by benchmark scripts: native_target NAME builds the native target NAME in the
# Maven-built tree (target/native, or ARFLEX_NATIVE_DIR) if its binary is missing, configuring
# the tree first if needed, and prints the binary's path. Needs ROOT (the checkout).
native_target() {
  local build=${ARFLEX_NATIVE_DIR:-$ROOT/target/native}
  if [ ! -x "$build/bin/$1" ]; then
    [ -f "$build/build.ninja" ] || cmake -S "$ROOT" -B "$build" -G Ninja >/dev/null
    cmake --build "$build" -j2 --target "$1" >&2
  fi
  echo "$build/bin/$1"
}
