#!/usr/bin/env bash
# Refresh the firmware budget table (flash, static RAM, panic paths, instruction counts,
# CPU load) in docs/budgets.md. Needs qemu-system-arm and the thumbv7em-none-eabihf
# target; runs the same check CI runs (tests/tests/fw_budgets.rs) and keeps its table.
set -euo pipefail
cd "$(dirname "$0")/.."
out="$PWD/docs/budgets.md"
table="$(mktemp)"
stack="$(mktemp)"
trap 'rm -f "$table" "$stack"' EXIT
FOG_REQUIRE_QEMU=1 FOG_BUDGETS_OUT="$table" \
    cargo test -p fog-tests --test fw_budgets -- --nocapture
FOG_REQUIRE_QEMU=1 FOG_BUDGETS_STACK_OUT="$stack" \
    cargo test -p fog-tests --test qemu_replay -- --nocapture
{
    echo "# Firmware budgets"
    echo
    echo "Measured by \`scripts/budgets.sh\` on $(date -u +%Y-%m-%d) with $(rustc --version | cut -d' ' -f1-2)"
    echo "(\`cargo test -p fog-tests --test fw_budgets\` and \`--test qemu_replay\`; firmware profile \`fw\`, QEMU"
    echo "\`mps2-an386\` with \`-icount shift=0\`: instruction counts, not cycles)."
    echo
    cat "$table" "$stack"
} > "$out"
echo "wrote $out"
