#!/usr/bin/env bash
# Signing component bundles, with the JDK's keytool and jarsigner (README: Signing a component;
# docs/DECISIONS.md D14). Also: ./arflex sign ...
#
#   key    <keystore.p12> <alias> [<dname>]        make a signing key (EC P-256, 10 years) in a PKCS12 key store
#   sign   <bundle.jar> <keystore.p12> <alias>     sign a component bundle in place, then verify it
#   export <keystore.p12> <alias> <cert.crt>       write the key's certificate (PEM) for the runtimes that trust it
#   trust  <cert.crt> [<runtime-dir>]              make a runtime trust the key: copy the certificate into
#                                                  <runtime-dir>/trust/ (default: the runtime ./arflex run starts)
#
# The key store password is asked for, or taken from the environment variable ARFLEX_KEYSTORE_PASS
# (never from the command line, where other users could read it in the process list).
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
JBIN="${JAVA_HOME:+$JAVA_HOME/bin/}"
KEYTOOL="${JBIN}keytool"
JARSIGNER="${JBIN}jarsigner"

usage() {
  sed -n '2,12p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'
}

die() {
  echo "sign-component: $*" >&2
  exit 2
}

# The password options for keytool/jarsigner: from the environment if set, else they prompt.
pass() {
  if [ -n "${ARFLEX_KEYSTORE_PASS:-}" ]; then
    printf '%s\n' "-storepass:env" "ARFLEX_KEYSTORE_PASS"
  fi
}

cmd_key() {
  [ $# -ge 2 ] || die "usage: key <keystore.p12> <alias> [<dname>]"
  local store="$1" alias="$2" dname="${3:-CN=$2}"
  mapfile -t p < <(pass)
  ( umask 077; "$KEYTOOL" -genkeypair -keyalg EC -groupname secp256r1 -validity 3650 -alias "$alias" \
      -dname "$dname" -keystore "$store" -storetype PKCS12 "${p[@]}" )
  echo "sign-component: key '$alias' ($dname) in $store (mode 0600: keep it off the cell)"
}

cmd_sign() {
  [ $# -eq 3 ] || die "usage: sign <bundle.jar> <keystore.p12> <alias>"
  local jar="$1" store="$2" alias="$3"
  [ -f "$jar" ] || die "no such jar: $jar"
  mapfile -t p < <(pass)
  "$JARSIGNER" -keystore "$store" -storetype PKCS12 "${p[@]}" -digestalg SHA-256 "$jar" "$alias"
  # jarsigner warns that a self-signed certificate has no CA chain and that there is no timestamp:
  # both are expected here, the runtime trusts the certificate itself (D14).
  "$JARSIGNER" -verify "$jar"
}

cmd_export() {
  [ $# -eq 3 ] || die "usage: export <keystore.p12> <alias> <cert.crt>"
  local store="$1" alias="$2" out="$3"
  mapfile -t p < <(pass)
  "$KEYTOOL" -exportcert -rfc -alias "$alias" -keystore "$store" -storetype PKCS12 "${p[@]}" -file "$out"
  "$KEYTOOL" -printcert -file "$out" | grep -E '^(Owner|Valid|[[:space:]]*SHA256):'
}

cmd_trust() {
  [ $# -ge 1 ] && [ $# -le 2 ] || die "usage: trust <cert.crt> [<runtime-dir>]"
  local cert="$1" dir="${2:-$ROOT/management/runtime/target/arflex-runtime}"
  [ -d "$dir" ] || die "no runtime folder $dir (build it with ./arflex run, or name yours)"
  "$KEYTOOL" -printcert -file "$cert" >/dev/null 2>&1 || die "$cert is not an X.509 certificate"
  local name
  name=$(basename "$cert")
  case "$name" in *.crt|*.pem|*.cer) ;; *) name="$name.crt" ;; esac
  # The runtime refuses a trust store that group or others can write to, or a certificate file.
  install -d -m 0755 "$dir/trust"
  chmod go-w "$dir/trust"
  install -m 0644 "$cert" "$dir/trust/$name"
  echo "sign-component: $dir/trust/$name is trusted; bundles it signed run their RT halves from their next start:"
  "$KEYTOOL" -printcert -file "$dir/trust/$name" | grep -E '^(Owner|[[:space:]]*SHA256):'
}

case "${1:-}" in
  key) shift; cmd_key "$@" ;;
  sign) shift; cmd_sign "$@" ;;
  export) shift; cmd_export "$@" ;;
  trust) shift; cmd_trust "$@" ;;
  -h|--help|help) usage ;;
  *) usage >&2; exit 2 ;;
esac
