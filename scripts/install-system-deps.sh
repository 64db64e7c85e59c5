#!/usr/bin/env bash
# Install the Debian/Ubuntu packages of packages.txt that are missing.
#
#   scripts/install-system-deps.sh [GROUP...]     (default: every group)
#
# Works on Debian 12 and Ubuntu 22.04/24.04: a line "a|b" installs the first
# alternative apt has a candidate for (`apt-cache policy`), "{clang}" is the
# major version of the clang apt would install. A package apt cannot install
# is named with the reason and what it was for; a missing "core" package
# makes the script fail, a missing "test" package only skips some tests.
# Needs root for apt-get; without it, it prints the command to run.
# APT_OS_RELEASE and PATH can point elsewhere (tests/project/test_system_deps.py).
set -euo pipefail
cd "$(dirname "$0")/.."
os_release="${APT_OS_RELEASE:-/etc/os-release}"
system=$( (. "$os_release" 2>/dev/null && echo "${PRETTY_NAME:-unknown system}") || echo "unknown system")
want_groups=("$@")

in_groups() {
  [ ${#want_groups[@]} -eq 0 ] && return 0
  local g
  for g in "${want_groups[@]}"; do [ "$g" = "$1" ] && return 0; done
  return 1
}

installed() { dpkg -s "$1" 2>/dev/null | grep -q '^Status: install ok installed'; }

# The candidate version apt would install, empty when there is none.
candidate() {
  apt-cache policy "$1" 2>/dev/null | awk '/Candidate:/ {print $2; exit}' | grep -v '^(none)$' || true
}

# A package name with {clang} filled in. apt-cache policy takes most of a
# second, so clang's major version is looked up once, and only for names
# that hold {clang} (called in this shell, not in $(...), to keep it).
clang_major=""
name=""
resolve() {
  name=$1
  [[ "$name" == *"{clang}"* ]] || return 0
  if [ -z "$clang_major" ]; then
    local v
    v=$(candidate clang)
    [ -z "$v" ] && v=$(dpkg-query -W -f='${Version}' clang 2>/dev/null || true)
    v=${v#*:}                 # drop the epoch: 1:14.0-55.7 -> 14.0-55.7
    clang_major=${v%%[.~+-]*}
  fi
  name=${name//\{clang\}/$clang_major}
}

# Lines of packages.txt in the wanted groups: "alternatives<TAB>group<TAB>why".
entries=()
while IFS= read -r line; do
  [[ "$line" =~ ^[[:space:]]*(#|$) ]] && continue
  why=""
  [[ "$line" == *"#"* ]] && why="${line#*# }"
  read -r alts group _ <<<"${line%%#*}"
  in_groups "${group:-core}" && entries+=("$alts"$'\t'"${group:-core}"$'\t'"$why")
done < packages.txt

missing=()      # entries none of whose alternatives is installed
for e in "${entries[@]}"; do
  IFS=$'\t' read -r alts group why <<<"$e"
  IFS='|' read -r -a parts <<<"$alts"
  found=0
  for p in "${parts[@]}"; do
    resolve "$p"
    installed "$name" && { found=1; break; }
  done
  [ $found = 1 ] || missing+=("$e")
done
[ ${#missing[@]} -eq 0 ] && exit 0

if [ "$(id -u)" != 0 ]; then
  names=()
  for e in "${missing[@]}"; do names+=("${e%%$'\t'*}"); done
  echo "note: missing packages (not root, so not installing them): ${names[*]}" >&2
  echo "      install them with: sudo bash scripts/install-system-deps.sh $*" >&2
  exit 0
fi

echo "system packages: updating apt's lists on $system ..."
DEBIAN_FRONTEND=noninteractive apt-get update -q
clang_major=""   # the lists may have changed clang's candidate
chosen=() failed_core=0
for e in "${missing[@]}"; do
  IFS=$'\t' read -r alts group why <<<"$e"
  IFS='|' read -r -a parts <<<"$alts"
  pick=""
  tried=()
  for p in "${parts[@]}"; do
    resolve "$p"
    tried+=("$name")
    [ -n "$(candidate "$name")" ] && { pick=$name; break; }
  done
  if [ -n "$pick" ]; then
    chosen+=("$pick")
  else
    echo "cannot install ${tried[*]}: apt has no installation candidate for it on $system (apt-cache policy). It is for: $why" >&2
    [ "$group" = core ] && failed_core=1
  fi
done
if [ ${#chosen[@]} -gt 0 ]; then
  echo "system packages: installing ${chosen[*]} ..."
  DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${chosen[@]}"
fi
if [ $failed_core = 1 ]; then
  echo "error: a package grading needs cannot be installed on $system (see above)." >&2
  exit 1
fi
