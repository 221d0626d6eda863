#!/usr/bin/env bash
# Installs what flume-twin needs on a fresh Debian/Ubuntu machine: a Vulkan driver (Mesa's
# lavapipe, the software Vulkan device, when no GPU driver is present) and checks for cargo.
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

if ! have_vulkan_icd; then
  echo "no Vulkan driver found: installing mesa-vulkan-drivers (lavapipe, software Vulkan)" >&2
  sudo_cmd=""
  if [ "$(id -u)" -ne 0 ]; then sudo_cmd="sudo"; fi
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq mesa-vulkan-drivers >/dev/null
fi

# Mesa's device-select layer complains on stderr when this is unset; it is harmless but noisy.
if [ -z "${XDG_RUNTIME_DIR:-}" ] || [ ! -d "${XDG_RUNTIME_DIR}" ]; then
  export XDG_RUNTIME_DIR="${TMPDIR:-/tmp}/flume-twin-runtime-$(id -u)"
  mkdir -p "$XDG_RUNTIME_DIR"
  chmod 700 "$XDG_RUNTIME_DIR"
fi
