#!/usr/bin/env bash
# The Web Console's TLS key for remote use (scripts/run-cell.sh, ARFLEX_CONSOLE_HOST beyond
# loopback): the console is then served over HTTPS only.
#   console-tls.sh ARFLEX_HOME HOST
# - ARFLEX_CONSOLE_KEYSTORE (a PKCS12 file) and ARFLEX_CONSOLE_KEYSTORE_PASSWORD set: the
#   integrator's own certificate, used as it is;
# - else ARFLEX_HOME/console-tls.p12, generated at first use (EC P-256, self-signed, 825 days,
#   names: this host, HOST, localhost), its random password in console-tls.pass; both 0600.
#   Its SHA-256 fingerprint is printed so that a browser's warning can be checked against it.
# Prints two lines: the keystore's path, then the file holding its password.
set -euo pipefail
home=${1:?usage: console-tls.sh ARFLEX_HOME HOST}
host=${2:?usage: console-tls.sh ARFLEX_HOME HOST}
if [ -n "${ARFLEX_CONSOLE_KEYSTORE:-}" ]; then
  [ -r "$ARFLEX_CONSOLE_KEYSTORE" ] || { echo "arflex: ARFLEX_CONSOLE_KEYSTORE '$ARFLEX_CONSOLE_KEYSTORE' is not a readable file" >&2; exit 2; }
  [ -n "${ARFLEX_CONSOLE_KEYSTORE_PASSWORD:-}" ] || { echo "arflex: ARFLEX_CONSOLE_KEYSTORE needs ARFLEX_CONSOLE_KEYSTORE_PASSWORD" >&2; exit 2; }
  pass=$(umask 077 && mktemp "$home/console-tls.XXXXXX.pass")
  printf '%s' "$ARFLEX_CONSOLE_KEYSTORE_PASSWORD" > "$pass"
  keytool -list -keystore "$ARFLEX_CONSOLE_KEYSTORE" -storetype PKCS12 -storepass:file "$pass" >/dev/null 2>&1 \
    || { rm -f "$pass"; echo "arflex: cannot open $ARFLEX_CONSOLE_KEYSTORE as PKCS12 with the given password" >&2; exit 2; }
  printf '%s\n%s\n' "$ARFLEX_CONSOLE_KEYSTORE" "$pass"
  exit 0
fi
mkdir -p "$home" && chmod 700 "$home"
ks="$home/console-tls.p12"
pass="$home/console-tls.pass"
if [ ! -f "$ks" ] || [ ! -f "$pass" ]; then
  rm -f "$ks" "$pass"
  (umask 077 && head -c 24 /dev/urandom | base64 | tr '+/' '-_' | tr -d '\n' > "$pass")
  san="dns:localhost,ip:127.0.0.1,dns:$(hostname)"
  if [[ "$host" =~ ^[0-9.]+$ ]] && [ "$host" != "0.0.0.0" ]; then san="$san,ip:$host"
  elif [[ "$host" =~ ^[A-Za-z0-9.-]+$ ]] && [ "$host" != "0.0.0.0" ]; then san="$san,dns:$host"; fi
  (umask 077 && keytool -genkeypair -alias console -keyalg EC -groupname secp256r1 -validity 825 \
    -dname "CN=ARFLEX console $(hostname)" -ext "SAN=$san" -keystore "$ks" -storetype PKCS12 \
    -storepass:file "$pass" >/dev/null 2>&1) || { rm -f "$ks" "$pass"; echo "arflex: keytool could not make $ks" >&2; exit 2; }
  echo "arflex: web console TLS certificate generated in $ks (self-signed); its SHA-256 fingerprint:" >&2
  keytool -list -keystore "$ks" -storetype PKCS12 -storepass:file "$pass" -alias console -v 2>/dev/null \
    | sed -n 's/^[[:space:]]*SHA256: /  /p' >&2
fi
chmod 600 "$ks" "$pass"
printf '%s\n%s\n' "$ks" "$pass"
