#!/usr/bin/env python3
"""Board fit: builds the `fit` image for each detector configuration and part, records
whether it links (or the region the linker says it overflows), and prints Markdown tables.

For each configuration: one image for QEMU mps2-an386 (no board) gives the per-frame
instructions (mean and worst), the stack (the whole run's, set-up included, and the
step's) and the state and frame sizes; with --cycles, `faint-cycles run` on the same
image gives Cortex-M4 and Cortex-M7 (approximation) cycles per frame (for a configuration
that fits some part). Then, per part,
the image is linked with the part's memory.x and the stack room the run measured
(FAINT_FIT_STACK), trying the part's placements of state and frame in order; the first
that links is kept. With --run-f407 every STM32F407 image that links runs on QEMU
netduinoplus2 and must print the mps2 image's counts and report hash.

A family's configurations are tried largest first; once every part has one that fits,
the smaller ones are not built. Each configuration's result is kept in
target/fit/<spec>.json (--cached prints the tables from those files without building;
delete them after a change to the detectors).

--add-cycles runs faint-cycles on the kept images that fit some part and have no cycles yet.

usage: boards/fit.py [--quick] [--cycles] [--run-f407] [--only FAMILY,...] [--fresh] [--cached | --add-cycles]
Run from firmware/. Needs qemu-system-arm, llvm-size; --cycles needs
target/tools/release/faint-cycles (firmware/README.md, "Cycles").
"""

import json
import math
import os
import re
import subprocess
import sys

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
FIRMWARE = os.path.join(ROOT, "firmware")
OUT = os.path.join(ROOT, "target", "fit")
# A target folder of its own: the FAINT_* variables rebuild the firmware crate, which would
# otherwise make the next plain `cargo run` in firmware/ rebuild every image.
CARGO_DIR = os.path.join(OUT, "cargo")
ELF = os.path.join(CARGO_DIR, "thumbv7em-none-eabihf", "firmware", "fit")
CYCLES = os.path.join(ROOT, "target", "tools", "release", "faint-cycles")
QEMU = ["qemu-system-arm", "-nographic", "-semihosting-config", "enable=on,target=native",
        "-icount", "shift=10,align=off,sleep=off"]
MPS2 = QEMU + ["-cpu", "cortex-m4", "-machine", "mps2-an386", "-kernel"]
NETDUINO = QEMU + ["-machine", "netduinoplus2", "-kernel"]

# Parts: clock (MHz), core, RAM regions (name -> bytes), output section -> region, and the
# placements (state section, frame section) tried in order (fastest memory first; on the
# STM32F407 a frame in CCM suits a frame the CPU copies in, not a DMA buffer).
PARTS = {
    "stm32f407": dict(mhz=168, core="M4", regions={"FLASH": 1024 << 10, "RAM": 128 << 10, "CCM": 64 << 10},
                      sections={"ram": "RAM", ".ccm": "CCM"},
                      placements=[("ram", "ram"), (".ccm", "ram"), ("ram", ".ccm")]),
    "stm32h743": dict(mhz=480, core="M7", regions={"FLASH": 2048 << 10, "RAM": 128 << 10, "AXISRAM": 512 << 10,
                                                   "SRAM123": 288 << 10, "SRAM4": 64 << 10},
                      sections={"ram": "RAM", ".axisram": "AXISRAM", ".sram123": "SRAM123", ".sram4": "SRAM4"},
                      placements=[(".axisram", ".sram123"), (".sram123", ".axisram")]),
    "atsame70q21": dict(mhz=300, core="M7", regions={"FLASH": 2048 << 10, "RAM": 384 << 10},
                        sections={"ram": "RAM"}, placements=[("ram", "ram")]),
}

# Detectors: (family, paper's frame period in s, period source, configurations largest
# first; the first is the firmware table's configuration).
FAMILIES = [
    ("crpf", 0.64, "paper", ["crpf:6000", "crpf:2000", "crpf:1500", "crpf:1000", "crpf:250"]),
    ("pf-tbd", 0.64, "CRPF-TBD's", ["pf-tbd:6000", "pf-tbd:2000", "pf-tbd:1000", "pf-tbd:250"]),
    ("jott", 0.64, "CRPF-TBD's", ["jott:6000", "jott:2000", "jott:1000", "jott:250"]),
    ("pf-lrt", 0.64, "CRPF-TBD's", ["pf-lrt:6000", "pf-lrt:2000", "pf-lrt:1000", "pf-lrt:250"]),
    ("mht", 5.0, "paper, per scan", ["mht:512", "mht:448", "mht:432", "mht:416"]),
    ("hough", 5.0, "MHT-TBD's", ["hough"]),
    ("phd", 1.0, "PSO-PHD-TBD's", ["phd:6144:1024:32", "phd:2048:1024:32", "phd:1024:128:16",
                                   "phd:256:64:16"]),
    ("pso-phd", 1.0, "paper", ["pso-phd:6144:1024:32", "pso-phd:2048:1024:32", "pso-phd:2048:256:32",
                               "pso-phd:1024:128:16",
                               "pso-phd:256:64:16"]),
    ("cbmember", 1.0, "chosen: the preset's dt", ["cbmember:1000"]),
    ("dp-first", 1.0, "chosen", ["dp-first:128:16", "dp-first:128:8", "dp-first:64:16"]),
    ("dp-pulford", 1.0, "chosen", ["dp-pulford:128", "dp-pulford:64", "dp-pulford:32"]),
    ("dp-second", 1.0, "chosen", ["dp-second:128:16", "dp-second:128:8", "dp-second:64:16",
                                              "dp-second:32:16"]),
]
# The cheap subset (CI): one configuration per family at most, the F407's CCM + SRAM case.
QUICK = {"crpf": ["crpf:250"], "dp-first": ["dp-first:64:16"]}


def build(spec, board=None, state="ram", frame="ram", stack=None):
    env = dict(os.environ, FAINT_FIT=spec, FAINT_FIT_STATE=state, FAINT_FIT_FRAME=frame,
               CARGO_TARGET_DIR=CARGO_DIR)
    for k in ("FAINT_BOARD", "FAINT_FIT_STACK"):
        env.pop(k, None)
    if board:
        env["FAINT_BOARD"] = board
    if stack:
        env["FAINT_FIT_STACK"] = str(stack)
    p = subprocess.run(["cargo", "build", "-q", "--profile", "firmware", "--bin", "fit"], cwd=FIRMWARE,
                       env=env, capture_output=True, text=True)
    if p.returncode == 0:
        return None
    # lld: "section '.ccm' will not fit in region 'CCM': overflowed by N bytes";
    # GNU ld: "region `CCM' overflowed by N bytes".
    m = re.search(r"region [`']([A-Za-z0-9_]+)':? overflowed by (\d+) bytes", p.stderr)
    if m:
        return f"{m.group(1)} overflowed by {m.group(2)} B"
    sys.exit(f"fit.py: build of {spec} for {board or 'mps2-an386'} failed:\n{p.stderr[-3000:]}")


def sections(elf):
    out = subprocess.run(["llvm-size", "-A", elf], capture_output=True, text=True, check=True).stdout
    return {l.split()[0]: int(l.split()[1]) for l in out.splitlines()[2:] if len(l.split()) == 3}


def run(cmd, elf):
    p = subprocess.run(cmd + [elf], capture_output=True, text=True, timeout=3000)
    if p.returncode != 0 or "done" not in p.stdout:
        sys.exit(f"fit.py: {elf} failed on {cmd[-2]}:\n{p.stdout[-2000:]}{p.stderr[-2000:]}")
    r = {}
    for l in p.stdout.splitlines():
        f = [x.strip() for x in l.split("|")]
        if l.startswith("fit | ") and len(f) >= 9 and f[2] != "" and not f[1].startswith("board"):
            r.update(frames=int(f[3]), mean=int(f[4]), worst=int(f[5]), step_stack=int(f[6]), hash=f[7])
        elif l.startswith("fit sizes"):
            m = re.findall(r"(\d+) B in (\S+)", l)
            r.update(state=int(m[0][0]), frame=int(m[1][0]), harness=int(m[2][0]))
        elif l.startswith("fit stack"):
            r.update(stack=int(re.search(r"run (\d+) B", l).group(1)))
    r["steps"] = [int(x.split("|")[4]) for x in p.stdout.splitlines() if x.startswith("region | step")]
    return r


def cycles(elf, spec):
    p = subprocess.run([CYCLES, "run", elf], capture_output=True, text=True, timeout=3000)
    if p.returncode != 0:
        sys.exit(f"fit.py: faint-cycles on {spec} failed:\n{p.stderr[-2000:]}")
    m4, m7 = [], []
    for l in p.stdout.splitlines():
        f = [x.strip() for x in l.split("|")]
        if l.startswith(f"| {spec} frame") and len(f) > 8:
            m4.append(int(f[4]))
            m7.append(int(f[7]))
    return m4, m7


def flash(sec):
    return sum(sec.get(s, 0) for s in (".vector_table", ".text", ".rodata", ".data"))


def region_use(part, sec, place):
    """Bytes per RAM region of a linked image."""
    use = {}
    for name, size in sec.items():
        region = None
        if name in (".data", ".bss", ".uninit", ".stack_reserve"):
            region = "RAM"
        elif name in PARTS[part]["sections"]:
            region = PARTS[part]["sections"][name]
        if region and size:
            use[region] = use.get(region, 0) + size
    return use


def kib(n):
    return f"{n / 1024:.1f}"


def main():
    args = sys.argv[1:]
    quick = "--quick" in args
    with_cycles = "--cycles" in args or "--cached" in args
    run_f407 = "--run-f407" in args
    cached = "--cached" in args
    fresh = "--fresh" in args
    only = None
    if "--only" in args:
        only = args[args.index("--only") + 1].split(",")
    os.makedirs(OUT, exist_ok=True)
    if "--add-cycles" in args:
        # Cycles for the kept results that have none, from their mps2-an386 images.
        for family, _, _, specs in FAMILIES:
            for spec in specs:
                if only and family not in only:
                    continue
                cache = os.path.join(OUT, spec.replace(":", "-") + ".json")
                if not os.path.exists(cache):
                    continue
                with open(cache) as f:
                    r = json.load(f)
                if "m4" in r or not any(v["ok"] for v in r["parts"].values()):
                    continue
                m4, m7 = cycles(os.path.join(OUT, spec.replace(":", "-") + ".mps2.elf"), spec)
                r["m4"] = (sum(m4) // max(len(m4), 1), max(m4, default=0))
                r["m7"] = (sum(m7) // max(len(m7), 1), max(m7, default=0))
                with open(cache, "w") as f:
                    json.dump(r, f)
                print(f"fit.py: {spec}: cycles added", file=sys.stderr)
        return
    rows, fits = [], []
    for family, period, source, specs in FAMILIES:
        if only and family not in only:
            continue
        if quick:
            if family not in QUICK:
                continue
            specs = QUICK[family]
        best = {}
        for spec in specs:
            if len(best) == len(PARTS):
                break
            cache = os.path.join(OUT, spec.replace(":", "-") + ".json")
            # A kept result: always with --cached, otherwise unless --fresh or --quick.
            if os.path.exists(cache) and (cached or (not fresh and not quick)):
                with open(cache) as f:
                    r = json.load(f)
                rows.append((family, spec, r))
                for part in PARTS:
                    if r["parts"][part]["ok"] and part not in best:
                        best[part] = (spec, r)
                continue
            if cached:
                continue
            build(spec)
            elf = os.path.join(OUT, spec.replace(":", "-") + ".mps2.elf")
            os.replace(ELF, elf)
            r = run(MPS2, elf)
            sec = sections(elf)
            r["flash"] = flash(sec)
            stack = int(math.ceil((r["stack"] + 512) / 1024.0)) * 1024
            r["parts"] = {}
            for part, p in PARTS.items():
                result = None
                for i, (state, frame) in enumerate(p["placements"]):
                    # A placement after the first whose statics alone exceed a region is
                    # not linked (the first always is: the linker's own word).
                    need = {}
                    for sec_name, size in ((state, r["state"]), (frame, r["frame"] + r["harness"]),
                                           ("ram", stack)):
                        reg = p["sections"][sec_name]
                        need[reg] = need.get(reg, 0) + size
                    over = [(g, n - p["regions"][g]) for g, n in need.items() if n > p["regions"][g]]
                    if i > 0 and over:
                        err = f"{over[0][0]} short by {over[0][1]} B (not linked: statics and stack alone)"
                        result["err"] += f"; {state}/{frame}: " + err
                        continue
                    err = build(spec, part, state, frame, stack)
                    if err is None:
                        pelf = os.path.join(OUT, f"{spec.replace(':', '-')}.{part}.elf")
                        os.replace(ELF, pelf)
                        use = region_use(part, sections(pelf), (state, frame))
                        result = dict(ok=True, state=state, frame=frame, use=use, elf=pelf)
                        # QEMU 7.2's netduinoplus2 maps no CCM: CCM images link only.
                        if part == "stm32f407" and run_f407 and ".ccm" not in (state, frame):
                            f = run(NETDUINO, pelf)
                            # Same report hash; counts within a few instructions per frame (the
                            # two links place code and statics at other addresses, so a
                            # constant may take MOVW+MOVT instead of one MOV).
                            diff = max((abs(a - b) for a, b in zip(f["steps"], r["steps"])), default=0)
                            if f["hash"] != r["hash"] or len(f["steps"]) != len(r["steps"]) or diff > 16:
                                sys.exit(f"fit.py: {spec} on netduinoplus2 differs from mps2-an386")
                            result["ran"] = diff
                        break
                    if result is None:
                        result = dict(ok=False, err=f"{state}/{frame}: " + err, state=state, frame=frame)
                    else:
                        result["err"] += f"; {state}/{frame}: " + err
                r["parts"][part] = result
                if result["ok"] and part not in best:
                    best[part] = (spec, r)
            # Cycles (a traced run, the slow part) only for a configuration some part fits.
            if with_cycles and any(v["ok"] for v in r["parts"].values()):
                m4, m7 = cycles(elf, spec)
                r["m4"] = (sum(m4) // max(len(m4), 1), max(m4, default=0))
                r["m7"] = (sum(m7) // max(len(m7), 1), max(m7, default=0))
            rows.append((family, spec, r))
            if not quick:
                with open(cache, "w") as f:
                    json.dump(r, f)
            print(f"fit.py: {spec}: " + ", ".join(
                f"{k} {'links' if v['ok'] else v['err']}" for k, v in r["parts"].items()), file=sys.stderr)
        fits.append((family, period, source, specs, best))
    print_tables(rows, fits, with_cycles)


def print_tables(rows, fits, with_cycles):
    print("| configuration | frames | instructions / frame, mean | worst | "
          + ("M4 cycles / frame, mean | worst | M7 cycles / frame, mean | worst | " if with_cycles else "")
          + "stack, run (B) | stack, step (B) | state (B) | frame (B) | harness (B) | flash (B) |"
          + " STM32F407 | STM32H743 | ATSAME70Q21 |")
    print("|---|---:|---:|---:|" + ("---:|---:|---:|---:|" if with_cycles else "") + "---:|---:|---:|---:|---:|---:|---|---|---|")
    for family, spec, r in rows:
        cells = []
        for part in PARTS:
            v = r["parts"][part]
            if v["ok"]:
                use = ", ".join(f"{k} {kib(b)}" for k, b in sorted(v["use"].items()))
                ran = f"; ran, counts within {v['ran']}" if "ran" in v else ""
                cells.append(f"links ({use} KiB{ran})")
            else:
                cells.append(f"{v['err']}")
        cyc = ""
        if with_cycles and "m4" in r:
            cyc = f"{r['m4'][0]} | {r['m4'][1]} | {r['m7'][0]} | {r['m7'][1]} | "
        elif with_cycles:
            cyc = "- | - | - | - | "
        print(f"| `{spec}` | {r['frames']} | {r['mean']} | {r['worst']} | {cyc}{r['stack']} | {r['step_stack']} | "
              f"{r['state']} | {r['frame']} | {r.get('harness', '-')} | {r['flash']} | " + " | ".join(cells) + " |")
    print()
    print("| detector | frame period (s) | part | largest configuration that fits | worst frame | time at the part's clock (ms) | real time (margin) |")
    print("|---|---:|---|---|---:|---:|---|")
    for family, period, source, specs, best in fits:
        for part, p in PARTS.items():
            if part not in best:
                print(f"| {family} | {period} ({source}) | {part} | none of {', '.join(specs)} | - | - | no |")
                continue
            spec, r = best[part]
            if with_cycles and "m4" in r:
                worst = r["m4" if p["core"] == "M4" else "m7"][1]
                unit = f"{p['core']} cycles"
            else:
                worst = r["worst"]
                unit = "instructions"
            ms = worst / (p["mhz"] * 1e3)
            margin = period * 1e3 / ms if ms > 0 else float("inf")
            ok = "yes" if margin >= 1 else "no"
            print(f"| {family} | {period} ({source}) | {part} | `{spec}` | {worst} {unit} | {ms:.2f} | {ok} ({margin:.1f}x) |")


if __name__ == "__main__":
    main()
