# Shared by .ci/test and .ci/main: install what a fresh Debian machine with only the Rust
# toolchain lacks, or say exactly what is missing.
set -euo pipefail

# Each step is stamped with the seconds since the script started (bash's SECONDS), so a log
# shows where the time goes.
say() { printf '==> [%5d s] %s\n' "$SECONDS" "$*"; }

need_cmd() {
  command -v "$1" >/dev/null 2>&1 || { say "missing: $1 ($2)"; exit 1; }
}

# apt_ensure PKG... : install the Debian packages not yet installed (as root), else explain.
apt_ensure() {
  local missing=()
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  if [ "$(id -u)" -eq 0 ] && command -v apt-get >/dev/null 2>&1; then
    say "installing ${missing[*]} (apt-get)"
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  else
    say "missing Debian packages: ${missing[*]}"
    say "install them with: sudo apt-get install ${missing[*]}"
    exit 1
  fi
}

rust_target_ensure() {
  if ! rustup target list --installed 2>/dev/null | grep -qx "$1"; then
    need_cmd rustup "to add the Rust target $1"
    say "adding Rust target $1 (rustup)"
    rustup target add "$1"
  fi
}

cd "$(dirname "${BASH_SOURCE[0]}")/.."
need_cmd cargo "the Rust toolchain, from rustup"
