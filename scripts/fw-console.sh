#!/usr/bin/env bash
# Runs fog-app under QEMU (mps2-an386) and shows its two console channels decoded:
# - semihosting stdout carries defmt's binary frames -> `defmt-print -e ELF` (needs the
#   same ELF that runs; installed with `cargo install defmt-print --version 1.2.0
#   --locked`, which this script offers to do);
# - semihosting stderr carries the plain-text `FOG-...` lines the QEMU tests read.
# The two never mix: defmt-semihosting writes only to stdout, the text lines only to
# stderr. Usage:
#   scripts/fw-console.sh [--seconds N] [firmware-arg ...]    e.g. gyro-rate=200
# UART0..2 (host, gyro, turntable) are not connected here (serial null); docs/guide/firmware.md
# gives the QEMU line with the three ports for a rig. The ELF is the `cargo fw-build
# --target-dir target/fw` one (FOG_APP_ELF overrides).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=5
if [[ "${1:-}" == "--seconds" ]]; then
    seconds=$2
    shift 2
fi
elf=${FOG_APP_ELF:-target/fw/thumbv7em-none-eabihf/fw/fog-app}
if ! command -v defmt-print >/dev/null 2>&1; then
    echo "fw-console: defmt-print not found; install it with:" >&2
    echo "  cargo install defmt-print --version 1.2.0 --locked" >&2
    exit 2
fi
if [[ ! -f "$elf" ]]; then
    echo "fw-console: $elf not found; build it with: cargo fw-build --target-dir target/fw" >&2
    exit 2
fi
semi="enable=on,target=native,arg=fog-app"
for a in "$@"; do
    if [[ "$a" == *,* ]]; then
        echo "fw-console: argument $a: semihosting arguments cannot contain ','" >&2
        exit 2
    fi
    semi+=",arg=$a"
done
# stderr (text) is tagged [text], stdout (defmt) goes through the decoder.
timeout --foreground "$seconds" qemu-system-arm -machine mps2-an386 -cpu cortex-m4 \
    -nographic -monitor none -semihosting-config "$semi" -serial null -kernel "$elf" \
    2> >(sed -u 's/^/[text] /' >&2) | defmt-print -e "$elf" || true
