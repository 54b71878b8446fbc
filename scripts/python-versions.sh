#!/usr/bin/env bash
# Run the non-ROS test suite on the other Python versions navseq supports: CPython 3.10
# (ROS 2 Humble, Ubuntu 22.04) and 3.12 (ROS 2 Jazzy, Ubuntu 24.04). Debian 12 has only
# 3.11, which `make test` uses; the test machine carries the other two, built for it
# (../shared/python, see its README). `make test-pythons` runs this script; `.ci/run`
# calls it after `make test`. Without the archives it says so and does nothing.
#
# For each archive cpython-X.Y-*.tar.zst: unpack it into $NAVSEQ_PYTHON_PREFIX/X.Y
# (default /opt/navseq-python; a stamp file keeps a second run from unpacking the same
# archive again, and the tree is swapped in whole, as scripts/install-ros2-min.sh does),
# make .venvXY (navseq editable with its dev tools: plain `pip install -e '.[dev]'`, so
# pip picks the dependencies' versions for that Python), then run
# `python -m pytest -q -m "not ros and not ros2 and not browser"` in it. The ROS and
# browser tests need Debian's Python 3.11 (ROS 1, the ROS 2 tree) and run in `make test`.
#
# Where the archives are looked for: $NAVSEQ_PYTHON_ARCHIVES (a folder), then
# ../shared/python/ next to the repository, then /work/shared/python/.
# Arguments: the versions to run (default: every archive found), e.g. `3.10`.
# Extra pytest arguments: $NAVSEQ_PYTEST_ARGS (e.g. "tests/test_yaml_fast_path.py");
# workers: $NAVSEQ_TEST_WORKERS (default 4: the tests wait on the processes they start
# about half the time, so more workers than the machine's 2 cores pay, as in `make test`).
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
cd "$repo"
prefix="${NAVSEQ_PYTHON_PREFIX:-/opt/navseq-python}"

archive_dir="${NAVSEQ_PYTHON_ARCHIVES:-}"
if [ -z "$archive_dir" ]; then
  for dir in "$repo/../shared/python" /work/shared/python; do
    if ls "$dir"/cpython-*.tar.zst >/dev/null 2>&1; then archive_dir="$dir"; break; fi
  done
fi
if [ -z "$archive_dir" ] || ! ls "$archive_dir"/cpython-*.tar.zst >/dev/null 2>&1; then
  echo "python-versions: no Python archives found (../shared/python); nothing run"
  exit 0
fi

versions=("$@")
if [ ${#versions[@]} -eq 0 ]; then
  for archive in "$archive_dir"/cpython-*.tar.zst; do
    name=$(basename "$archive")
    name=${name#cpython-}
    versions+=("${name%%-*}")
  done
fi

if [ "$(id -u)" != 0 ]; then SUDO=sudo; else SUDO=; fi
if ! command -v zstd >/dev/null; then
  if ! command -v apt-get >/dev/null || { [ -n "$SUDO" ] && ! command -v sudo >/dev/null; }; then
    echo "python-versions: zstd is needed to unpack the archives and cannot be installed; nothing run"
    exit 0
  fi
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends zstd
fi

# Unpack X.Y into $prefix/X.Y unless the stamp says this archive is there already.
unpack() {
  local version=$1 archive=$2
  local tree="$prefix/$version"
  local stamp="$tree/.navseq-archive"
  local signature
  signature="$(basename "$archive") $(stat -c %s "$archive")"
  if [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$signature" ]; then
    return
  fi
  $SUDO mkdir -p "$prefix"
  $SUDO rm -rf "$prefix/.partial-$version"
  $SUDO mkdir -p "$prefix/.partial-$version"
  $SUDO tar --zstd -xf "$archive" -C "$prefix/.partial-$version"
  echo "$signature" | $SUDO tee "$prefix/.partial-$version/$version/.navseq-archive" >/dev/null
  # Swap in the complete tree only: an interrupted unpack never looks installed.
  $SUDO rm -rf "$tree"
  $SUDO mv "$prefix/.partial-$version/$version" "$tree"
  $SUDO rm -rf "$prefix/.partial-$version"
  echo "python-versions: Python $version unpacked in $tree"
}

# The venv is (re)installed when pyproject.toml or setup.py is newer than its stamp.
make_venv() {
  local version=$1
  local venv=".venv${version//./}"
  local python="$prefix/$version/bin/python$version"
  local stamp="$venv/.installed"
  if [ ! -x "$venv/bin/python" ]; then
    "$python" -m venv "$venv"
  fi
  if [ -f "$stamp" ] && [ "$stamp" -nt pyproject.toml ] && [ "$stamp" -nt setup.py ]; then
    return
  fi
  "$venv/bin/python" -m pip install -q --upgrade pip
  "$venv/bin/python" -m pip install -q -e '.[dev]'
  touch "$stamp"
}

# The ROS 2, Nav2 and browser checks belong to `make test`'s run: here they are not
# expected (rclpy is built for Debian's Python 3.11 and would not import).
unset NAVSEQ_EXPECT_ROS2 NAVSEQ_EXPECT_NAV2 NAVSEQ_EXPECT_BROWSER
read -r -a pytest_args <<< "${NAVSEQ_PYTEST_ARGS:-}"
status=0
for version in "${versions[@]}"; do
  archive=$(ls "$archive_dir"/cpython-"$version"-*.tar.zst 2>/dev/null | head -n 1 || true)
  if [ -z "$archive" ]; then
    echo "python-versions: no archive for Python $version in $archive_dir" >&2
    exit 2
  fi
  unpack "$version" "$archive"
  make_venv "$version"
  venv=".venv${version//./}"
  # pytest-xdist (a dev extra) spreads the tests over the workers.
  workers=()
  if "$venv/bin/python" -c 'import xdist' 2>/dev/null; then
    workers=(-n "${NAVSEQ_TEST_WORKERS:-4}" --dist worksteal)
  fi
  echo "python-versions: Python $("$venv/bin/python" -c 'import platform; print(platform.python_version())'): non-ROS tests"
  start=$SECONDS
  if ! "$venv/bin/python" -m pytest -q -p no:cacheprovider "${workers[@]}" \
      -m "not ros and not ros2 and not browser" "${pytest_args[@]}"; then
    status=1
  fi
  echo "python-versions: Python $version took $((SECONDS - start)) s"
done
exit $status
