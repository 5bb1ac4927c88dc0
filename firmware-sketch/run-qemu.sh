#!/usr/bin/env bash
# Cargo runner for the ARC firmware: boots ELF in QEMU (an STM32F405 board,
# netduinoplus2) and decodes the defmt frames that the firmware writes to
# semihosting stdout. The exit status is QEMU's: 0 only when the firmware
# exited through semihosting with success.
#   usage: run-qemu.sh FIRMWARE.elf
# QEMU_TIMEOUT (seconds, default 120) bounds a run that hangs.
set -uo pipefail
elf="$1"
for tool in qemu-system-arm defmt-print; do
  if ! command -v "$tool" >/dev/null 2>&1; then
    echo "run-qemu.sh: $tool not found (apt-get install qemu-system-arm; cargo install defmt-print)" >&2
    exit 127
  fi
done
timeout --foreground "${QEMU_TIMEOUT:-120}" \
  qemu-system-arm -cpu cortex-m4 -machine netduinoplus2 -nographic \
    -semihosting-config enable=on,target=native -kernel "$elf" \
  | defmt-print -e "$elf"
status=("${PIPESTATUS[@]}")
exit "${status[0]}"
