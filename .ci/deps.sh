#!/usr/bin/env bash
# Installs the Debian 12 packages sandbench needs, only those missing.
# Idempotent and quick when everything is present; uses sudo when not root.
set -euo pipefail

packages=(
  build-essential cmake pkg-config git
  libeigen3-dev libcgal-dev libgmp-dev libmpfr-dev libboost-dev
  libhdf5-dev libpng-dev libosmesa6-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libcli11-dev libtomlplusplus-dev nlohmann-json3-dev
  python3-numpy python3-matplotlib python3-h5py python3-jinja2
  libglfw3-dev libimgui-dev xvfb xauth
  munge slurmctld slurmd slurm-client  # the slurm test's own cluster (it starts and stops the daemons)
  libopenvdb-dev libtbb-dev
  libcairo2-dev fonts-dejavu-core libepoxy-dev
  clang-format
  lammps  # `make dem` and the test suite's tiny particle case; `make reproduce` never runs it
)

# `deps.sh fuzz` adds clang and its libFuzzer runtime (for `make fuzz` only); `deps.sh lint`
# clang-tidy (for `make lint`; clang-format is always installed: CI checks the formatting).
if [[ "${1:-}" == "fuzz" ]]; then
  packages+=(clang libclang-rt-14-dev)
elif [[ "${1:-}" == "lint" ]]; then
  packages+=(clang-tidy)
fi

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$p")
done

if ((${#missing[@]} == 0)); then
  exit 0
fi

echo "deps: installing ${missing[*]}" >&2
sudo_cmd=()
if [[ $(id -u) -ne 0 ]]; then
  # Neither root nor a usable sudo: say what to install rather than fail on a missing command
  # (sudo that asks for a password works only from a terminal).
  if ! command -v sudo >/dev/null 2>&1 || { ! [[ -t 0 ]] && ! sudo -n true 2>/dev/null; }; then
    echo "deps: missing Debian packages: ${missing[*]}" >&2
    echo "deps: installing them needs root or sudo, and neither is available here; as root run:" >&2
    echo "  apt-get install --no-install-recommends ${missing[*]}" >&2
    exit 2
  fi
  sudo_cmd=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
