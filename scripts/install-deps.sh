#!/usr/bin/env bash
# Installs the Debian (bookworm) packages oalservo needs, only those that are missing,
# without prompts. Uses sudo when not run as root. With package names as arguments, those
# instead (scripts/slurm-check.sh: slurm-wlm munge).
set -euo pipefail

packages=(
  g++ cmake make pkg-config
  libvisp-dev visp-images-data opencv-doc
  libopencv-dev libopencv-contrib-dev libeigen3-dev
  libyaml-cpp-dev libcli11-dev nlohmann-json3-dev libxml2-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libjs-chart.js chromium
  gnuplot-nox
  libcairo2-dev fonts-dejavu-core librsvg2-bin imagemagick gsfonts poppler-utils xvfb
  pybind11-dev python3-pybind11 python3-numpy python3-pytest
)
if [ $# -gt 0 ]; then packages=("$@"); fi

missing=()
for package in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$package")
  fi
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages are installed"
  exit 0
fi

sudo=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
  sudo="sudo"
fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
