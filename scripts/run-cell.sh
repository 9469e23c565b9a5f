#!/usr/bin/env bash
# Starts the assembled runtime (Felix + DRCR + console) and installs the cell's component
# bundles into it from the Gogo shell, as an integrator would. Called by `./arflex run`.
#   run-cell.sh RUNTIME_DIR [HEADLESS_SECONDS]
# Interactive: after the cell is installed, your terminal is the Gogo shell (try `arflex:list`,
# `lb`, `help`); end it with `stop 0` or Ctrl-D. A one-line summary of the cell (components
# active, robot cycles, the vision-measured and the TRUE TCP error) is printed every 10 s on
# stderr. Headless: `arflex:list` and the summary every 5 s, then the runtime stops cleanly
# after HEADLESS_SECONDS.
# The runtime runs as an evaluation run (-Darflex.evaluation=true): sim-robot publishes the
# simulator's ground truth (the true TCP), which only this summary reads (simulator/README.md,
# "Ground truth"). ARFLEX_EVALUATION=false turns it off.
set -euo pipefail
# Everything the runtime creates (felix-cache, the extracted RT executables, logs) is private to
# its user: under umask 000 another user could replace an RT executable that runs as root
# (issue 16 finding 5; the DRCR also sets its own folders 0700 and checks every executable's
# SHA-256 before it spawns it).
umask 077
RUNTIME_DIR=${1:?runtime directory}
HEADLESS=${2:-}
# rt-core's shared-memory offsets for the summary below, generated from its headers.
LAYOUT_ENV=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)/layout.env
cd "$RUNTIME_DIR"

if [ -n "$HEADLESS" ] && ! [[ "$HEADLESS" =~ ^[0-9]+$ ]]; then
  echo "arflex run: --headless takes whole seconds, not '$HEADLESS'" >&2
  exit 2
fi

# Web Console credentials (scripts/console-login.sh): ARFLEX_CONSOLE_USER/ARFLEX_CONSOLE_PASSWORD
# when set, otherwise the private file in ARFLEX_HOME generated at first start (its password
# printed once). Only the hash is stored, mode 0600.
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

# The runtime's output also goes to a private log, so the command feeder below can wait for the
# DRCR to be up before it types (Gogo starts reading before the DRCR's commands exist).
LOG=$(mktemp "$ARFLEX_HOME/runtime.XXXXXX.log")
trap 'rm -f "$LOG" "$CONF" ${CREDS_TMP:+"$CREDS_TMP"} ${TLS_PASS:+"$TLS_PASS"}' EXIT

# The cell's summary, read straight from the ports in shared memory (state seqlock of slot 0,
# rt-core ABI.md §4) at the offsets of scripts/layout.env, generated from rt-core's headers
# (docs/DECISIONS.md D22). The TRUE error is |true TCP - nominal FK of
# the program's reference| at rest (the same definition as the accuracy benchmark); the nominal
# forward kinematics are the simulator's default arm (simulator/README.md, "The arm").
summary() {
  local rid
  rid=$(sed -n 's/.*arflex: DRCR started, runtime id \([a-z0-9-]*\),.*/\1/p' "$LOG" | head -1)
  [ -n "$rid" ] || return 0
  python3 - "$rid" "$LAYOUT_ENV" <<'PY' >&2 || true
import glob, math, mmap, struct, sys
rid = sys.argv[1]
with open(sys.argv[2]) as f:
    L = {k: int(v, 0) for k, v in (l.strip().split("=", 1) for l in f if "=" in l and not l.startswith("#"))}
SEQ = L["PORT_HDR_SIZE"] + L["OFF_SLOT_HDR_SEQ"]  # slot 0's seqlock word
VAL = L["PORT_HDR_SIZE"] + L["SLOT_HDR_SIZE"]     # slot 0's value
def port(inst, name, size):
    path = "/dev/shm/arflex.%s.%s.out.%s" % (rid, inst, name)
    try:
        with open(path, "rb") as f:
            m = mmap.mmap(f.fileno(), VAL + size, prot=mmap.PROT_READ)
    except OSError:
        return None
    for _ in range(100):
        s1 = struct.unpack_from("<Q", m, SEQ)[0]
        if s1 == 0:
            return None
        if s1 & 1:
            continue
        v = m[VAL:VAL + size]
        if struct.unpack_from("<Q", m, SEQ)[0] == s1:
            return v
    return None
def fk(q):
    offs = [(0, 0, 0), (0.35, 0, 0.675), (0, 0, 1.15), (0.5, 0, 0.041), (0.7, 0, 0), (0.215, 0, 0)]
    axes = "zyyxyx"
    R = [[1, 0, 0], [0, 1, 0], [0, 0, 1]]
    p = [0.0, 0.0, 0.0]
    def rot(a, t):
        c, s = math.cos(t), math.sin(t)
        return {"x": [[1, 0, 0], [0, c, -s], [0, s, c]], "y": [[c, 0, s], [0, 1, 0], [-s, 0, c]],
                "z": [[c, -s, 0], [s, c, 0], [0, 0, 1]]}[a]
    mul = lambda A, B: [[sum(A[i][k] * B[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
    app = lambda A, v: [sum(A[i][k] * v[k] for k in range(3)) for i in range(3)]
    for o, a, t in zip(offs, axes, q):
        p = [p[i] + d for i, d in enumerate(app(R, o))]
        R = mul(R, rot(a, t))
    return [p[i] + d for i, d in enumerate(app(R, (0.3, 0, 0)))]
ctls = glob.glob("/dev/shm/arflex.%s.*.ctl" % rid)
parts = ["%d RT halves running" % len(ctls)]
waiting = []
for c in sorted(ctls):
    try:
        with open(c, "rb") as f:
            f.seek(L["OFF_CTL_FLAGS"])
            flags = struct.unpack("<I", f.read(4))[0]
    except OSError:
        continue
    if flags & L["FLAG_RESET_REQUIRED"]:  # safe mode until the operator's reset
        waiting.append(c.split("/arflex.%s." % rid, 1)[1][:-4])
if waiting:
    parts.append("WAITING FOR AN OPERATOR RESET (safe mode): %s (arflex:reset <name>)" % " ".join(waiting))
js = port("sim-robot", "joint_state", 160)
if js:
    parts.append("robot seq %d" % struct.unpack_from("<Q", js, 8)[0])
err = port("tcp-correction", "error", 24)
if err:
    parts.append("vision-measured TCP error %.4f mm (measurement %d)" % (struct.unpack_from("<d", err, 16)[0], struct.unpack_from("<Q", err, 0)[0]))
corr = port("tcp-correction", "correction", 24)
if corr:
    parts.append("correction %.3f mrad" % struct.unpack_from("<d", corr, 16)[0])
ref = port("trajectory", "joint_ref", 64)
truth = port("sim-robot", "truth", 192)
if ref and truth and js:
    q = struct.unpack_from("<6d", ref, 16)
    qd = struct.unpack_from("<6d", js, 64)
    t = struct.unpack_from("<3d", truth, 40)
    e = math.dist(t, fk(q))
    moving = max(abs(v) for v in qd) > 1e-3
    parts.append("TRUE TCP error %.4f mm%s" % (1e3 * e, " (moving)" if moving else " (at rest)"))
print("arflex cell: " + ("; ".join(parts) if parts else "no cell ports yet"))
PY
}

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

await_active() {
  local deadline=$((SECONDS + 60))
  until grep -q "arflex: $1 ACTIVE" "$LOG"; do
    if [ $SECONDS -ge $deadline ]; then
      echo "echo 'arflex run: $1 is not ACTIVE after 60 s; its settings in conf/cell.gosh are skipped'"
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
      arflex:set\ *)
        # A parameter is set on the running component: a value set before its bundle's start
        # has been processed is replaced by the contract's defaults when it starts.
        await_active "$(set -- $line; echo "$2")"
        printf '%s\n' "$line" ;;
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
      summary
    done
    echo "stop 0"
  else
    # the live summary on stderr while the user types into the shell
    ( while sleep 10; do summary; done ) &
    SUMMARY_PID=$!
    cat
    kill "$SUMMARY_PID" 2>/dev/null || true
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
commands | "${NICE[@]}" java "${JVM_OPTS[@]}" "${SYSPROPS[@]}" -Dfelix.config.properties="file:$CONF" \
  -Dfelix.system.properties="file:$CREDS" -Darflex.console.bundles="$console_bundles" \
  -Darflex.home="$ARFLEX_HOME" -Darflex.evaluation="${ARFLEX_EVALUATION:-true}" -jar bin/felix.jar 2>&1 | tee "$LOG"
