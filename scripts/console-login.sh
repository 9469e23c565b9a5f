#!/usr/bin/env bash
# The Web Console's login for the main job (scripts/run-cell.sh). There is no default password:
#   console-login.sh ARFLEX_HOME
# - ARFLEX_CONSOLE_PASSWORD set (ARFLEX_CONSOLE_USER, default arflex): a private temporary
#   properties file with that login, removed by the caller when it is done;
# - else ARFLEX_HOME/console.properties, generated at first start with a random password that
#   is printed once, here, and never again.
# Only the SHA-256 hash is stored (the form the Web Console checks), mode 0600, in a mode 0700
# folder. Prints the properties file's path as the last line of stdout.
set -euo pipefail
home=${1:?usage: console-login.sh ARFLEX_HOME}
mkdir -p "$home" && chmod 700 "$home"
creds="$home/console.properties"
hash_password() {
  python3 -c 'import base64,hashlib,sys; print("{sha-256}" + base64.b64encode(hashlib.sha256(sys.stdin.buffer.read()).digest()).decode())'
}
user=${ARFLEX_CONSOLE_USER:-arflex}
if ! [[ "$user" =~ ^[A-Za-z0-9._-]{1,64}$ ]]; then
  echo "arflex: ARFLEX_CONSOLE_USER '$user': use 1-64 letters, digits, '.', '_' or '-'" >&2
  exit 2
fi
if [ -n "${ARFLEX_CONSOLE_PASSWORD:-}" ]; then
  creds=$(umask 077 && mktemp "$home/console.XXXXXX.properties")
  { echo "felix.webconsole.username=$user"
    echo "felix.webconsole.password=$(printf '%s' "$ARFLEX_CONSOLE_PASSWORD" | hash_password)"; } > "$creds"
elif [ ! -f "$creds" ]; then
  password=$(head -c 18 /dev/urandom | base64 | tr '+/' '-_')
  (umask 077 && { echo "felix.webconsole.username=arflex"
                  echo "felix.webconsole.password=$(printf '%s' "$password" | hash_password)"; } > "$creds")
  echo "arflex: web console login generated (shown once, only its hash is kept in $creds):"
  echo "arflex:   user arflex, password $password"
fi
chmod 600 "$creds"
echo "$creds"
