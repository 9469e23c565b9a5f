#!/usr/bin/env bash
# Starts the assembled runtime (Felix + DRCR + console) and installs the cell's component
# bundles into it from the Gogo shell, as an integrator would. Called by `./arflex run`.
#   run-cell.sh RUNTIME_DIR [HEADLESS_SECONDS]
# Interactive: after the cell is installed, your terminal is the Gogo shell (try `arflex:list`,
# `arflex:summary`, `lb`, `help`); end it with `stop 0` or Ctrl-D. Once the whole cell is ACTIVE
# (arflex:await --cell) the shell prints `arflex:list` and the cell's one-line summary
# (`arflex:summary`: RT halves running, robot cycles, the vision-measured and the TRUE TCP
# error). Headless: `arflex:list`, `arflex:stats sim-robot` and the summary every 5 s, then the
# runtime stops cleanly HEADLESS_SECONDS after the start.
# ARFLEX_SHIELD_CPUS (./arflex run --shield CPUS): every other process is kept off those CPUs
# while the runtime runs, and the runtime's JVM (with it the non-real-time threads of the RT
# halves) runs on the others; ARFLEX_SHIELD_POLL=true (--poll) keeps them from idling
# (scripts/rt-shield.sh, docs/DECISIONS.md D59).
# The runtime runs as an evaluation run (-Darflex.evaluation=true): sim-robot publishes the
# simulator's ground truth (the true TCP), which only the summary reads (simulator/README.md,
# "Ground truth"). ARFLEX_EVALUATION=false turns it off.
# ARFLEX_CELL_GOSH (./arflex run --empty: /dev/null): the commands that install the cell instead
# of conf/cell.gosh; with none, the runtime (DRCR, shell, console) comes up with no component, and
# the headless loop prints only `arflex:list` (D84).
set -euo pipefail
# Everything the runtime creates (felix-cache, the extracted RT executables, logs) is private to
# its user: under umask 000 another user could replace an RT executable that runs as root
# (issue 16 finding 5; the DRCR also sets its own folders 0700 and checks every executable's
# SHA-256 before it spawns it).
umask 077
RUNTIME_DIR=${1:?runtime directory}
HEADLESS=${2:-}
cd "$RUNTIME_DIR"
CELL_GOSH=${ARFLEX_CELL_GOSH:-conf/cell.gosh}

if [ -n "$HEADLESS" ] && ! [[ "$HEADLESS" =~ ^[0-9]+$ ]]; then
  echo "arflex run: --headless takes whole seconds, not '$HEADLESS'" >&2
  exit 2
fi

# Web Console credentials (scripts/console-login.sh): ARFLEX_CONSOLE_USER/ARFLEX_CONSOLE_PASSWORD
# when set, otherwise the private file in ARFLEX_HOME generated at first start (its password
# printed once). Only a salted slow hash is stored (PBKDF2), mode 0600.
ARFLEX_HOME=${ARFLEX_HOME:-$HOME/.arflex}
login=$("$(dirname "${BASH_SOURCE[0]}")/console-login.sh" "$ARFLEX_HOME")
CREDS=$(printf '%s\n' "$login" | tail -n 1)
printf '%s\n' "$login" | sed '$d'
[ -n "${ARFLEX_CONSOLE_PASSWORD:-}" ] && CREDS_TMP=$CREDS
console_bundles=$(for jar in console/*.jar; do printf 'file:%s ' "$RUNTIME_DIR/$jar"; done)
port=$(sed -n 's/^org.osgi.service.http.port=//p' conf/config.properties)

# The framework's configuration, a private copy per start (it may carry the TLS key's password).
# The console listens on loopback (conf/config.properties); ARFLEX_CONSOLE_HOST beyond loopback
# (or ARFLEX_CONSOLE_TLS=true on loopback) serves it over HTTPS only, plain HTTP off
# (scripts/console-tls.sh: your PKCS12 key, or one generated in ARFLEX_HOME), and the console
# refuses plain requests that reach it from beyond loopback anyway (docs/DECISIONS.md D16).
CONF=$(umask 077 && mktemp "$ARFLEX_HOME/config.XXXXXX.properties")
trap 'rm -f "$CONF"' EXIT
cp conf/config.properties "$CONF"
# The console's login is ours (ConsoleLogin: salted slow hash, back-off, audited; D81): the Web
# Console serves nothing until that provider is there, and its own password check is off.
echo "felix.webconsole.security.providers=arflex" >> "$CONF"
host=${ARFLEX_CONSOLE_HOST:-127.0.0.1}
TLS_PASS=
tls=${ARFLEX_CONSOLE_TLS:-}
case "$host" in 127.*|localhost|::1) [ "$tls" = true ] || tls=false ;; *) tls=true ;; esac
case "$tls" in
  false)
    echo "arflex: web console at http://127.0.0.1:${port:-8480}/system/console (user from $CREDS)" ;;
  true)
    if ! [[ "$host" =~ ^[A-Za-z0-9.:-]+$ ]]; then
      echo "arflex run: ARFLEX_CONSOLE_HOST '$host' is not a host name or address" >&2; exit 2
    fi
    keys=$("$(dirname "${BASH_SOURCE[0]}")/console-tls.sh" "$ARFLEX_HOME" "$host")
    ks=$(printf '%s\n' "$keys" | sed -n 1p)
    TLS_PASS=$(printf '%s\n' "$keys" | sed -n 2p)
    sport=${ARFLEX_CONSOLE_HTTPS_PORT:-8443}
    { echo "org.apache.felix.http.host=$host"
      echo "org.osgi.service.http.host=$host"
      echo "org.apache.felix.http.enable=false"
      echo "org.apache.felix.https.enable=true"
      echo "org.osgi.service.http.port.secure=$sport"
      echo "org.apache.felix.https.keystore=$ks"
      echo "org.apache.felix.https.keystore.type=PKCS12"
      echo "org.apache.felix.https.keystore.password=$(cat "$TLS_PASS")"
      echo "org.apache.felix.https.keystore.key.password=$(cat "$TLS_PASS")"; } >> "$CONF"
    case "$TLS_PASS" in "$ARFLEX_HOME"/console-tls.pass) TLS_PASS= ;; esac # the generated one stays
    echo "arflex: web console at https://$host:$sport/system/console only (HTTPS; user from $CREDS)" ;;
esac
# JVM system properties of the assembly (conf/system.properties: URL connection timeouts), which
# felix.system.properties below would otherwise replace.
SYSPROPS=()
while IFS= read -r line; do
  case "$line" in "#"*|"") ;; *=*) SYSPROPS+=("-D$line") ;; esac
done < conf/system.properties
trap 'rm -f "$CONF" ${CREDS_TMP:+"$CREDS_TMP"} ${TLS_PASS:+"$TLS_PASS"}' EXIT
TASKSET=()
if [ -n "${ARFLEX_SHIELD_CPUS:-}" ]; then
  SHIELD="$(dirname "${BASH_SOURCE[0]}")/rt-shield.sh"
  TASKSET=(taskset -c "$("$SHIELD" rest --cpus "$ARFLEX_SHIELD_CPUS")")
  "$SHIELD" on --cpus "$ARFLEX_SHIELD_CPUS" --keep $$ $([ "${ARFLEX_SHIELD_POLL:-}" = true ] && echo --poll)
  trap 'rm -f "$CONF" ${CREDS_TMP:+"$CREDS_TMP"} ${TLS_PASS:+"$TLS_PASS"}; "$SHIELD" off' EXIT
fi

# What is typed into the console (our shell bundle, docs/DECISIONS.md D28): it reads its first
# line once the framework has started every bundle, so the DRCR's arflex:* commands exist by then;
# readiness comes from the DRCR (arflex:await), the summary from arflex:summary, nothing from the
# log (docs/DECISIONS.md D31).
commands() {
  if [ "$CELL_GOSH" = /dev/null ]; then
    echo "echo 'ARFLEX runtime up; no cell (--empty): install components with start file:<bundle.jar>'"
  else
    echo "echo 'ARFLEX runtime up; installing the cell ($CELL_GOSH)'"
  fi
  # Felix's start installs a bundle from its URL and starts it; the DRCR's extender then reads
  # its contract, plans, and starts its RT half once its inputs are satisfied.
  local line name awaited=" " cell=
  while IFS= read -r line || [ -n "$line" ]; do
    case "$line" in
      "#"*|"") ;;
      start\ *)
        cell=yes
        printf '%s\n' "${line//@CELL@/$RUNTIME_DIR/cell}" ;;
      arflex:set\ *)
        # A parameter is set on the running component: a value set before its bundle's start
        # has been processed is replaced by the contract's defaults when it starts. The console
        # runs one line after the other, so the set waits for the await.
        name=$(set -- $line; echo "$2")
        case "$awaited" in
          *" $name "*) ;;
          *) echo "arflex:await $name ACTIVE --timeout 60"; awaited="$awaited$name " ;;
        esac
        printf '%s\n' "$line" ;;
      *) printf '%s\n' "${line//@CELL@/$RUNTIME_DIR/cell}" ;;
    esac
  done < "$CELL_GOSH"
  # the console answers once the whole cell is ACTIVE (or says which component is not, and why);
  # a cell.gosh that starts nothing (the browser tests' own) is not waited for
  if [ -n "$cell" ]; then
    echo "arflex:await --cell --timeout 120"
  fi
  echo "arflex:list"
  if [ -n "$cell" ]; then
    echo "arflex:summary"
  fi
  if [ -n "$HEADLESS" ]; then
    local end=$((SECONDS + HEADLESS))
    while [ $SECONDS -lt $end ]; do
      sleep 5
      echo "arflex:list"
      if [ -n "$cell" ]; then
        echo "arflex:stats sim-robot"
        echo "arflex:summary"
      fi
    done
    echo "stop 0"
  else
    cat
  fi
}

# The runtime's heartbeat thread (in the JVM, SCHED_OTHER) must not be starved by the cell's
# best-effort work (camera rendering, vision; those run at nice 19): the JVM runs at nice -10
# where the user may raise priorities (root or CAP_SYS_NICE), else at the default.
NICE=()
if nice -n -10 true 2>/dev/null && [ "$(nice -n -10 nice)" = "-10" ]; then NICE=(nice -n -10); fi
# arflex.home: where the console keeps its audit log (console-audit.log, mode 0600).
# G1's default pause goal is 200 ms, twice the 100 ms runtime heartbeat timeout of the 1 kHz
# components: a collection during the cell's start-up put sim-robot into safe mode now and then.
JVM_OPTS=(-XX:+UseG1GC -XX:MaxGCPauseMillis=20)
commands | "${TASKSET[@]}" "${NICE[@]}" java "${JVM_OPTS[@]}" "${SYSPROPS[@]}" -Dfelix.config.properties="file:$CONF" \
  -Dfelix.system.properties="file:$CREDS" -Darflex.console.bundles="$console_bundles" \
  -Darflex.home="$ARFLEX_HOME" -Darflex.evaluation="${ARFLEX_EVALUATION:-true}" -jar bin/felix.jar 2>&1
