#!/usr/bin/env bash
# Installs the Debian bookworm packages leaflux needs to build, test and run its demo.
# Runs apt-get directly as root, through sudo otherwise. Safe to run again.
set -euo pipefail

packages=(
    build-essential cmake ninja-build pkg-config git
    libembree-dev libglm-dev libtbb-dev
    libzmq3-dev cppzmq-dev
    libprotobuf-dev protobuf-compiler
    libspdlog-dev libfmt-dev
    libgtest-dev libgmock-dev libbenchmark-dev
    libsqlite3-dev libcli11-dev libpugixml-dev libpng-dev
    python3 python3-zmq python3-protobuf python3-matplotlib python3-numpy
    python3-venv python3-pip python3-setuptools python3-pytest python3-pandas
    default-jdk-headless libjeromq-java libprotobuf-java
)

missing=()
for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "${#missing[@]}" -eq 0 ]; then
    exit 0
fi

if [ "$(id -u)" -eq 0 ]; then
    sudo=()
else
    sudo=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo[@]}" apt-get update -qq
"${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
