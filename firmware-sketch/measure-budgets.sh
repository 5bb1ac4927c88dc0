#!/usr/bin/env bash
# Measures the ARC firmware's memory budgets and checks them:
#   flash for code + constants (without the table)  <= 96 KiB
#   static RAM (.data + .bss + .uninit)              <= 16 KiB
#   stack peak (painted stack, measured in QEMU)     <= 8 KiB
# for two table sizes (N_SRS = 100 and 1000 by default), and checks that RAM
# does not grow with the table (the table stays in its flash slot).
#
#   usage: firmware-sketch/measure-budgets.sh [N_SRS ...]
# Needs: the thumbv7em-none-eabihf target, llvm-size (cargo-binutils' rust-size,
# the llvm-tools component, or LLVM on PATH), qemu-system-arm and defmt-print.
# Exit status: 0 when every budget holds, 1 otherwise.
set -euo pipefail
cd "$(dirname "$0")"
sizes=("$@")
[ ${#sizes[@]} -gt 0 ] || sizes=(100 1000)

FLASH_BUDGET=$((96 * 1024))
RAM_BUDGET=$((16 * 1024))
STACK_BUDGET=$((8 * 1024))

# llvm-size: cargo-binutils, else the llvm-tools component, else PATH.
if command -v rust-size >/dev/null 2>&1; then
  size_tool=(rust-size)
else
  host=$(rustc -vV | sed -n 's/^host: //p')
  candidate="$(rustc --print sysroot)/lib/rustlib/$host/bin/llvm-size"
  if [ -x "$candidate" ]; then
    size_tool=("$candidate")
  elif command -v llvm-size >/dev/null 2>&1; then
    size_tool=(llvm-size)
  else
    echo "measure-budgets: no llvm-size (rustup component add llvm-tools)" >&2
    exit 2
  fi
fi

target_dir=../target/firmware
out_dir="$target_dir/budgets"
mkdir -p "$out_dir"

# Sum of the named sections' sizes in `llvm-size -A` output.
section_sum() {
  local elf=$1; shift
  "${size_tool[@]}" -A "$elf" | awk -v names=" $* " '
    index(names, " " $1 " ") { s += $2 } END { print s + 0 }'
}

status=0
declare -a rows
first_ram=""
for n in "${sizes[@]}"; do
  echo "== N_SRS=$n: building" >&2
  ARC_N_SRS=$n DEFMT_LOG=info cargo build --release --quiet
  elf="$out_dir/arc-firmware-nsrs$n.elf"
  cp "$target_dir/thumbv7em-none-eabihf/release/arc-firmware" "$elf"

  code=$(section_sum "$elf" .vector_table .text .rodata .data)
  table=$(section_sum "$elf" .arc_tables)
  ram=$(section_sum "$elf" .data .bss .uninit)

  echo "== N_SRS=$n: running in QEMU" >&2
  log="$out_dir/arc-firmware-nsrs$n.log"
  if ./run-qemu.sh "$elf" >"$log" 2>&1; then run="success"; else run="FAILED"; status=1; fi
  stack=$(sed -n 's/.*stack peak \([0-9]*\) bytes.*/\1/p' "$log" | tail -1)
  [ -n "$stack" ] || { stack=0; run="$run, no stack report"; status=1; }

  verdict=ok
  [ "$code" -le $FLASH_BUDGET ] || { verdict="OVER (flash)"; status=1; }
  [ "$ram" -le $RAM_BUDGET ] || { verdict="OVER (RAM)"; status=1; }
  [ "$stack" -le $STACK_BUDGET ] || { verdict="OVER (stack)"; status=1; }
  if [ -z "$first_ram" ]; then
    first_ram=$ram
  elif [ "$ram" -ne "$first_ram" ]; then
    verdict="$verdict; static RAM grew with the table"
    status=1
  fi
  rows+=("$(awk -v n="$n" -v c="$code" -v t="$table" -v r="$ram" -v s="$stack" \
    -v run="$run" -v v="$verdict" 'BEGIN {
      printf "| %6s | %8d B (%5.1f KiB) | %8d B (%5.1f KiB) | %6d B | %6d B | %s | %s |",
        n, c, c / 1024, t, t / 1024, r, s, run, v }')")
done

echo
echo "Budgets: code+constants <= 96 KiB flash, static RAM <= 16 KiB, stack peak <= 8 KiB"
echo
echo "| N_SRS  | flash: code + constants | flash: table slot used  | static RAM | stack peak | QEMU run | verdict |"
echo "|-------:|------------------------:|------------------------:|-----------:|-----------:|---------|---------|"
printf '%s\n' "${rows[@]}"
echo
echo "(size tool: ${size_tool[*]}; logs and ELFs in $out_dir)"
exit $status
