#!/usr/bin/env bash
# The Web Console's login for the main job (scripts/run-cell.sh). There is no default password:
#   console-login.sh ARFLEX_HOME
# - ARFLEX_CONSOLE_PASSWORD set (ARFLEX_CONSOLE_USER, default arflex): a private temporary
#   properties file with that login, removed by the caller when it is done;
# - else ARFLEX_HOME/console.properties, generated at first start with a random password that
#   is printed once, here, and never again.
# Only a salted slow hash is stored, {pbkdf2-sha256}<iterations>$<salt>$<hash> (PBKDF2-HMAC-SHA256,
# 600000 iterations, 16 random bytes of salt; the console's ConsoleLogin checks it), mode 0600, in
# a mode 0700 folder. A console.properties of an earlier version (an unsalted {sha-256} hash) is
# refused with what to do (docs/decisions/D81). Prints the properties file's path as the last
# line of stdout.
set -euo pipefail
home=${1:?usage: console-login.sh ARFLEX_HOME}
mkdir -p "$home" && chmod 700 "$home"
creds="$home/console.properties"
hash_password() {
  python3 -c 'import base64,hashlib,os,sys
n = 600000; salt = os.urandom(16)
h = hashlib.pbkdf2_hmac("sha256", sys.stdin.buffer.read(), salt, n)
print("{pbkdf2-sha256}%d$%s$%s" % (n, base64.b64encode(salt).decode(), base64.b64encode(h).decode()))'
}
user=${ARFLEX_CONSOLE_USER:-arflex}
if ! [[ "$user" =~ ^[A-Za-z0-9._-]{1,64}$ ]]; then
  echo "arflex: ARFLEX_CONSOLE_USER '$user': use 1-64 letters, digits, '.', '_' or '-'" >&2
  exit 2
fi
if [ -n "${ARFLEX_CONSOLE_PASSWORD:-}" ]; then
  creds=$(umask 077 && mktemp "$home/console.XXXXXX.properties")
  { echo "arflex.console.username=$user"
    echo "arflex.console.password=$(printf '%s' "$ARFLEX_CONSOLE_PASSWORD" | hash_password)"; } > "$creds"
elif [ -f "$creds" ] && ! grep -q '^arflex\.console\.password={pbkdf2-sha256}' "$creds"; then
  echo "arflex: $creds holds the console login of an earlier version (an unsalted SHA-256 hash, issue 30)," >&2
  echo "arflex: which is no longer accepted. Remove that file and start again to generate a new password" >&2
  echo "arflex: (printed once), or set ARFLEX_CONSOLE_PASSWORD (and ARFLEX_CONSOLE_USER)." >&2
  exit 2
elif [ ! -f "$creds" ]; then
  password=$(head -c 18 /dev/urandom | base64 | tr '+/' '-_')
  (umask 077 && { echo "arflex.console.username=arflex"
                  echo "arflex.console.password=$(printf '%s' "$password" | hash_password)"; } > "$creds")
  echo "arflex: web console login generated (shown once, only its hash is kept in $creds):"
  echo "arflex:   user arflex, password $password"
fi
chmod 600 "$creds"
echo "$creds"
