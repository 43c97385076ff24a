#!/usr/bin/env python3
"""Deepest static call path (stack bytes) below firmware functions, from the disassembly.

Why: the painted QEMU replay (tests/tests/qemu_replay.rs) says *how much* stack the boot
and the sample loop use; this says *which functions* use it, so a growth can be traced
to a frame (docs/explain/stack.md). A frame is what the prologue reserves: `push`/`push.w`
registers x 4 B, `vpush` registers x 4/8 B, `sub`/`subw`/`sub.w sp, #N`. Edges are
direct calls and tail branches (`bl`, `b.w`, `b` to another symbol); indirect calls
(`blx rN`) are not followed, so a path is a lower bound where those occur, and
recursion is cut. Thumb-2 code from `llvm-objdump -d` (rustup's llvm-tools).

Usage: scripts/stack_paths.py ELF FUNCTION_SUBSTRING...
  e.g. scripts/stack_paths.py target/fw/thumbv7em-none-eabihf/fw/replay \
           replay::__cortex_m_rt_main fog_firmware::replay::build
"""
import functools
import glob
import re
import subprocess
import sys

PUSH = re.compile(r"\tpush(?:\.w)?\t\{(.*)\}")
VPUSH = re.compile(r"\tvpush\t\{(.*)\}")
SUB_SP = re.compile(r"\tsub(?:w|\.w)?\tsp, (?:sp, )?#(0x[0-9a-f]+|\d+)")
CALL = re.compile(r"\t(?:bl|b\.w|b)\t0x[0-9a-f]+ <([^>+]*)>")
SYMBOL = re.compile(r"^[0-9a-f]+ <(.*)>:$")
MAX_DEPTH = 64


def objdump() -> str:
    sysroot = subprocess.run(
        ["rustc", "--print", "sysroot"], capture_output=True, text=True, check=True
    ).stdout.strip()
    found = glob.glob(f"{sysroot}/lib/rustlib/*/bin/llvm-objdump")
    if not found:
        sys.exit("stack_paths: llvm-objdump not found (rustup component add llvm-tools)")
    return found[0]


def vpush_bytes(regs: str) -> int:
    total = 0
    for r in (x.strip() for x in regs.split(",")):
        size = 8 if r.startswith("d") else 4
        a, _, b = r.partition("-")
        total += size * ((int(b[1:]) - int(a[1:]) + 1) if b else 1)
    return total


def parse(elf: str) -> dict:
    text = subprocess.run(
        [objdump(), "-d", "--no-show-raw-insn", "-C", elf],
        capture_output=True, text=True, check=True,
    ).stdout
    funcs, cur = {}, None
    for line in text.splitlines():
        m = SYMBOL.match(line)
        if m:
            cur = m.group(1)
            funcs[cur] = {"frame": 0, "calls": set()}
            continue
        if cur is None:
            continue
        f = funcs[cur]
        if m := PUSH.search(line):
            f["frame"] += 4 * len(m.group(1).split(","))
        elif m := VPUSH.search(line):
            f["frame"] += vpush_bytes(m.group(1))
        elif m := SUB_SP.search(line):
            f["frame"] += int(m.group(1), 0)
        elif (m := CALL.search(line)) and m.group(1) != cur:
            f["calls"].add(m.group(1))
    return funcs


def main() -> None:
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    funcs = parse(sys.argv[1])

    @functools.lru_cache(maxsize=None)
    def deepest(name: str, depth: int = 0) -> tuple:
        if name not in funcs or depth > MAX_DEPTH:
            return (0, ())
        below = max((deepest(c, depth + 1) for c in funcs[name]["calls"]), default=(0, ()))
        return (funcs[name]["frame"] + below[0], ((name, funcs[name]["frame"]),) + below[1])

    for want in sys.argv[2:]:
        name = next((n for n in funcs if want in n), None)
        if name is None:
            sys.exit(f"stack_paths: no function matching {want!r} in {sys.argv[1]}")
        total, path = deepest(name)
        print(f"{total} B deepest static path below {name}")
        for fn, frame in path:
            print(f"  {frame:6d}  {fn[:110]}")


if __name__ == "__main__":
    main()
