#!/usr/bin/env bash
# Installs the Debian packages of scripts/debian-packages.txt that are missing. Idempotent:
# installs nothing (and needs no root) when everything is already there.
#
# "#if-missing COMMAND PACKAGE" lines name a package installed only when COMMAND is not on the
# PATH (the dashboard's nodejs, npm and chromium: a machine with NodeSource's nodejs has node and
# npm already, and Debian's npm package would conflict with it).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
list="$here/debian-packages.txt"
mapfile -t wanted < <(grep -v '^\s*#' "$list" | sed '/^\s*$/d')
missing=()
for p in "${wanted[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
while read -r _ cmd pkg _; do
  wanted+=("$pkg")
  command -v "$cmd" >/dev/null 2>&1 || missing+=("$pkg")
done < <(grep '^#if-missing ' "$list")
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#wanted[@]} Debian packages present"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
sudo_cmd=()
[ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
