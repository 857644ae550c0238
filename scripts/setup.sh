#!/usr/bin/env bash
# Installs the Debian packages of a package list (default scripts/debian-packages.txt; `make
# fuzz` passes scripts/debian-packages-fuzz.txt), skipping apt when all are present. Works as root, or as a user with sudo. (The build itself goes to .build/, see the
# Makefile: a standalone catkin build of this package.)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

list="${1:-$root/scripts/debian-packages.txt}"
mapfile -t packages < <(grep -v '^\s*#' "$list" | awk 'NF {print $1}')
missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$p")
done

if ((${#missing[@]})); then
  echo "setup: installing ${#missing[@]} Debian package(s): ${missing[*]}"
  if [[ $(id -u) -eq 0 ]]; then
    sudo_cmd=()
  elif command -v sudo >/dev/null; then
    sudo_cmd=(sudo)
  else
    echo "setup: not root and no sudo; install these packages first: ${missing[*]}" >&2
    exit 1
  fi
  export DEBIAN_FRONTEND=noninteractive
  "${sudo_cmd[@]}" apt-get update -q
  "${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
else
  echo "setup: all ${#packages[@]} Debian packages present"
fi

