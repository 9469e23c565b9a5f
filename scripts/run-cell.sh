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

# Web Console credentials: ARFLEX_CONSOLE_USER / ARFLEX_CONSOLE_PASSWORD when set, otherwise
# the private file in ARFLEX_HOME, generated with a random password at first start (printed
# once). Only the SHA-256 hash is stored (the form the Web Console checks), mode 0600.
ARFLEX_HOME=${ARFLEX_HOME:-$HOME/.arflex}
mkdir -p "$ARFLEX_HOME" && chmod 700 "$ARFLEX_HOME"
CREDS="$ARFLEX_HOME/console.properties"
hash_password() {
  python3 -c 'import base64,hashlib,sys; print("{sha-256}" + base64.b64encode(hashlib.sha256(sys.stdin.buffer.read()).digest()).decode())'
}
if [ -n "${ARFLEX_CONSOLE_PASSWORD:-}" ]; then
  CREDS=$(mktemp "$ARFLEX_HOME/console.XXXXXX.properties")
  CREDS_TMP=$CREDS
  { echo "felix.webconsole.username=${ARFLEX_CONSOLE_USER:-arflex}"
    echo "felix.webconsole.password=$(printf '%s' "$ARFLEX_CONSOLE_PASSWORD" | hash_password)"; } > "$CREDS"
elif [ ! -f "$CREDS" ]; then
  password=$(head -c 18 /dev/urandom | base64 | tr '+/' '-_')
  (umask 077 && { echo "felix.webconsole.username=arflex"
                  echo "felix.webconsole.password=$(printf '%s' "$password" | hash_password)"; } > "$CREDS")
  echo "arflex: web console login generated (shown once, only its hash is kept in $CREDS):"
  echo "arflex:   user arflex, password $password"
fi
chmod 600 "$CREDS"
console_bundles=$(for jar in console/*.jar; do printf 'file:%s ' "$RUNTIME_DIR/$jar"; done)
port=$(sed -n 's/^org.osgi.service.http.port=//p' conf/config.properties)
echo "arflex: web console at http://127.0.0.1:${port:-8480}/system/console (user from $CREDS)"

# The runtime's output also goes to a private log, so the command feeder below can wait for the
# DRCR to be up before it types (Gogo starts reading before the DRCR's commands exist).
LOG=$(mktemp "$ARFLEX_HOME/runtime.XXXXXX.log")
trap 'rm -f "$LOG" ${CREDS_TMP:+"$CREDS_TMP"}' EXIT

await_drcr() {
  local deadline=$((SECONDS + 120))
  until grep -q "arflex: DRCR started" "$LOG"; do
    if [ $SECONDS -ge $deadline ]; then
      echo "echo 'arflex run: the DRCR did not start within 120 s; see the messages above'"
      return 1
    fi
    sleep 0.2
  done
}

commands() {
  await_drcr || { echo "stop 0"; return; }
  echo "echo 'ARFLEX runtime up; installing the cell (conf/cell.gosh)'"
  # Felix's start installs a bundle from its URL and starts it; the DRCR's extender then reads
  # its contract, plans, and starts its RT half once its inputs are satisfied.
  local line
  while IFS= read -r line || [ -n "$line" ]; do
    case "$line" in
      "#"*|"") ;;
      *) printf '%s\n' "${line//@CELL@/$RUNTIME_DIR/cell}" ;;
    esac
  done < conf/cell.gosh
  echo "arflex:list"
  if [ -n "$HEADLESS" ]; then
    local end=$((SECONDS + HEADLESS))
    while [ $SECONDS -lt $end ]; do
      sleep 5
      echo "arflex:list"
      echo "arflex:stats sim-robot"
    done
    echo "stop 0"
  else
    cat
  fi
}

commands | java -Dfelix.system.properties="file:$CREDS" -Darflex.console.bundles="$console_bundles" \
  -jar bin/felix.jar 2>&1 | tee "$LOG"
