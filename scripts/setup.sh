#!/usr/bin/env bash
# Installs the Debian packages leglab needs (only the missing ones), then configures the
# Release build in build/. Sourced by reproduce.sh and test.sh; safe to run again.
set -euo pipefail

LEGLAB_PACKAGES=(
  g++ cmake ninja-build pkg-config ccache
  libeigen3-dev libode-dev liburdfdom-dev liburdfdom-tools libyaml-cpp-dev libcli11-dev
  # The second physics engine (sim.engine: dart).
  libdart-dev
  libgtest-dev libgmock-dev libbenchmark-dev nlohmann-json3-dev
  python3 python3-matplotlib python3-numpy python3-pil clang-format clang-tidy parallel pmccabe
  # The Python sources' static check (ctest Checks.PythonHasNoPyflakesFindings).
  pyflakes3
  # leglab.results.animate reads the robot files with a YAML parser.
  python3-yaml
  # The Python package (python/, docs/python.md) and its tests.
  pybind11-dev python3-dev python3-pytest
  # The property-based test of the Python API (tests/python/test_properties.py).
  python3-hypothesis
  # The Python package's types: mypy over it and stubtest of its stub against the compiled
  # module (ctest Checks.PythonPackageIsTyped, Checks.PythonStubMatchesTheModule).
  python3-mypy
  # leglab.bus: servos on a serial port (pyserial), and socat for a pseudo-terminal pair in the
  # bus tests.
  python3-serial socat
  # The learned actuator models (leglab.servo.learned) and their tests.
  python3-torch
  # The results page's browser check (tests/python/results/report_test.py) and the
  # animation's encoder.
  chromium python3-websocket ffmpeg
)

missing=()
for p in "${LEGLAB_PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "leglab: installing ${missing[*]}"
  sudo_cmd=()
  if [ "$(id -u)" -ne 0 ]; then sudo_cmd=(sudo); fi
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends \
    "${missing[@]}"
fi

cd "$(dirname "$0")/.."
cmake --preset release >/dev/null
