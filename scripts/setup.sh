#!/usr/bin/env bash
# Installs what flume-twin needs on a fresh Debian/Ubuntu machine: a Vulkan driver (Mesa's
# lavapipe, the software Vulkan device, when no GPU driver is present), the DejaVu font for the
# labels of the bed plot, and checks for cargo.
# Sourced by scripts/run.sh and scripts/test.sh; safe to run again.
set -euo pipefail

if ! command -v cargo >/dev/null 2>&1; then
  echo "cargo not found: install Rust (https://rustup.rs), then run this again" >&2
  exit 1
fi

have_vulkan_icd() {
  for f in /usr/share/vulkan/icd.d/*.json /etc/vulkan/icd.d/*.json; do
    [ -e "$f" ] && return 0
  done
  return 1
}

# Debian 12's own Mesa (22.3) has a lavapipe that keeps memory with every step of the rheology
# pass and never gives it back: a wgpu run of the CI flume grows by 14-22 MB a second, past 8 GB
# in one test. Mesa 25 from Debian's own backports does not, and runs the same wgpu test about
# five times faster (README, "Software Vulkan").
debian_codename() {
  if [ -r /etc/os-release ]; then
    (. /etc/os-release && [ "${ID:-}" = "debian" ] && echo "${VERSION_CODENAME:-}")
  fi
}

if ! have_vulkan_icd; then
  sudo_cmd=""
  if [ "$(id -u)" -ne 0 ]; then sudo_cmd="sudo"; fi
  release=()
  if [ "$(debian_codename)" = "bookworm" ]; then
    echo "deb http://deb.debian.org/debian bookworm-backports main" |
      $sudo_cmd tee /etc/apt/sources.list.d/flume-twin-backports.list >/dev/null
    release=(-t bookworm-backports)
  fi
  echo "no Vulkan driver found: installing mesa-vulkan-drivers (lavapipe, software Vulkan)" \
    "${release[@]}" >&2
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq "${release[@]}" \
    mesa-vulkan-drivers >/dev/null
fi

# The bed plot draws without labels when the font is missing; install it where apt can.
if [ ! -e /usr/share/fonts/truetype/dejavu/DejaVuSans.ttf ] && command -v apt-get >/dev/null 2>&1; then
  echo "DejaVu Sans not found: installing fonts-dejavu-core (labels of the bed plot)" >&2
  sudo_cmd=""
  if [ "$(id -u)" -ne 0 ]; then sudo_cmd="sudo"; fi
  if ! { $sudo_cmd apt-get update -qq &&
    DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq fonts-dejavu-core >/dev/null; }; then
    echo "could not install fonts-dejavu-core: bed plots will have no labels" >&2
  fi
fi

# Mesa's device-select layer complains on stderr when this is unset; it is harmless but noisy.
if [ -z "${XDG_RUNTIME_DIR:-}" ] || [ ! -d "${XDG_RUNTIME_DIR}" ]; then
  export XDG_RUNTIME_DIR="${TMPDIR:-/tmp}/flume-twin-runtime-$(id -u)"
  mkdir -p "$XDG_RUNTIME_DIR"
  chmod 700 "$XDG_RUNTIME_DIR"
fi
