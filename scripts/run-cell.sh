#!/usr/bin/env bash
# Starts the assembled runtime (Felix + DRCR + console) and installs the cell's component
# bundles into it from the Gogo shell, as an integrator would. Called by `./arflex run`.
#   run-cell.sh RUNTIME_DIR [HEADLESS_SECONDS]
# Interactive: after the cell is installed, your terminal is the Gogo shell (try `arflex:list`,
# `lb`, `help`); end it with `stop 0` or Ctrl-D. Headless: prints a status every few seconds and
# stops the runtime cleanly after HEADLESS_SECONDS.
set -euo pipefail
RUNTIME_DIR=${1:?runtime directory}
HEADLESS=${2:-}
cd "$RUNTIME_DIR"

if [ -n "$HEADLESS" ] && ! [[ "$HEADLESS" =~ ^[0-9]+$ ]]; then
  echo "arflex run: --headless takes whole seconds, not '$HEADLESS'" >&2
  exit 2
fi

commands() {
  # Give the framework a moment to start the DRCR's shell commands; Gogo queues the input,
  # so this only orders the echo of the commands with the framework's own output.
  echo "echo 'ARFLEX runtime $(basename "$RUNTIME_DIR") up; installing the cell'"
  shopt -s nullglob
  for jar in cell/*.jar; do
    echo "install -s file:$RUNTIME_DIR/$jar"
  done
  echo "arflex:list"
  if [ -n "$HEADLESS" ]; then
    local end=$((SECONDS + HEADLESS))
    while [ $SECONDS -lt $end ]; do
      sleep 5
      echo "arflex:list"
    done
    echo "stop 0"
  else
    cat
  fi
}

commands | exec java -Xss2m -jar bin/felix.jar
