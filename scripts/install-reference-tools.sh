#!/usr/bin/env bash
# Installs the reference tools that the fixture scripts (scripts/fixtures/) and the benchmark
# comparisons (bench/) run: Octave with its control and signal packages, and python3-scipy.
# Not needed to build or test piezobench: the fixtures they produce are committed.
# Idempotent: nothing is installed when everything is present.
set -euo pipefail
packages=(octave octave-control octave-signal python3-scipy python3-numpy)
missing=()
for p in "${packages[@]}"; do
  if [ "$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null)" != "install ok installed" ]; then missing+=("$p"); fi
done
if [ ${#missing[@]} -gt 0 ]; then
  sudo_cmd=()
  if [ "$(id -u)" -ne 0 ]; then sudo_cmd=(sudo); fi
  "${sudo_cmd[@]}" apt-get update -q
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
fi
