#!/usr/bin/env bash
# Refresh the firmware budget table (flash, static RAM, panic paths, instruction counts,
# CPU load) in docs/budgets.md (and in the README, if it carries the budget markers). Needs qemu-system-arm and the thumbv7em-none-eabihf
# target; runs the same check CI runs (tests/tests/fw_budgets.rs) and keeps its table.
set -euo pipefail
cd "$(dirname "$0")/.."
out="$PWD/docs/budgets.md"
table="$(mktemp)"
stack="$(mktemp)"
board="$(mktemp)"
appstack="$(mktemp)"
trap 'rm -f "$table" "$stack" "$board" "$appstack"' EXIT
FOG_REQUIRE_QEMU=1 FOG_BUDGETS_OUT="$table" \
    cargo test -p fog-tests --test integration fw_budgets:: -- --nocapture
FOG_REQUIRE_QEMU=1 FOG_BUDGETS_STACK_OUT="$stack" \
    cargo test -p fog-tests --test integration qemu_replay:: -- --nocapture
FOG_REQUIRE_QEMU=1 FOG_BUDGETS_BOOT_STACK_OUT="$appstack" \
    cargo test -p fog-tests --test integration qemu_persist:: -- --nocapture
FOG_REQUIRE_QEMU=1 FOG_BUDGETS_BOARD_OUT="$board" \
    cargo test -p fog-tests --test integration board_budgets:: -- --nocapture
# Hand-written notes below the table (from the marker on) are kept.
notes="$(sed -n '/<!-- notes:begin -->/,$p' "$out" 2>/dev/null || true)"
{
    echo "# Firmware budgets"
    echo
    echo "Measured by \`scripts/budgets.sh\` on $(date -u +%Y-%m-%d) with $(rustc --version | cut -d' ' -f1-2)"
    echo "(\`cargo test -p fog-tests --test integration\` with \`fw_budgets::\`, \`qemu_replay::\` and \`qemu_persist::\`; firmware profile \`fw\`, QEMU"
    echo "\`mps2-an386\` with \`-icount shift=0\`: instruction counts, not cycles)."
    echo
    cat "$table" "$stack" "$appstack" "$board"
    if [ -n "$notes" ]; then
        echo
        echo "$notes"
    fi
} > "$out"
echo "wrote $out"

# A README that carries budget markers gets the same table between them.
readme="$PWD/README.md"
if grep -q '<!-- budgets:begin -->' "$readme"; then
    python3 - "$readme" "$table" "$stack" "$appstack" "$board" <<'PY'
import sys
readme, parts = sys.argv[1], sys.argv[2:]
text = open(readme).read()
begin, end = "<!-- budgets:begin -->", "<!-- budgets:end -->"
head, rest = text.split(begin, 1)
_, tail = rest.split(end, 1)
table = "".join(open(p).read() for p in parts).strip()
open(readme, "w").write(head + begin + "\n" + table + "\n" + end + tail)
PY
    echo "updated the budget table in $readme"
fi
