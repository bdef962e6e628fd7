#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# tools/setup's two package sets: `demo` (what tools/demo needs) is part of the full set (what
# tools/test needs), names no cross compiler, emulator, test framework or analysis tool, and holds
# the packages of every program tools/demo and tools/with-vcan run; an unknown set is refused.
#   setup_sets.sh ROOT
set -u
root=$1
fail() { echo "FAIL: $*"; exit 1; }
demo=$("$root/tools/setup" --list demo) || fail "tools/setup --list demo exited $?"
all=$("$root/tools/setup" --list) || fail "tools/setup --list exited $?"
[ -n "$demo" ] || fail "the demo set is empty"
for p in $demo; do
  grep -qx -- "$p" <<<"$all" || fail "$p is in the demo set but not in the full set"
done
[ "$(wc -l <<<"$all")" -gt "$(wc -l <<<"$demo")" ] || fail "the full set is no larger than the demo set"
for bad in arm-none-eabi aarch64 qemu valgrind clang stress-ng gtest gmock benchmark pybind python rt-tests gdb; do
  if grep -q -- "$bad" <<<"$demo"; then fail "the demo set names $bad: $(grep -- "$bad" <<<"$demo" | tr '\n' ' ')"; fi
done
# cmake, ninja, g++ (build-essential), pkg-config: the build; ip, modprobe, linux.uml: vcan0; gnuplot.
for need in build-essential cmake ninja-build pkg-config libsocketcan-dev iproute2 kmod user-mode-linux gnuplot-nox; do
  grep -qx -- "$need" <<<"$demo" || fail "the demo set lacks $need"
done
"$root/tools/setup" --list nonsense >/dev/null 2>&1
[ $? -eq 2 ] || fail "an unknown set is not refused with exit 2"
echo "ok: the demo set ($(wc -l <<<"$demo") packages) is part of the full set ($(wc -l <<<"$all")), no cross or test tools"
