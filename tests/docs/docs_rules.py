#!/usr/bin/env python3
"""Rules the documentation keeps (ctest: docs/docs_rules).

README.md <= 12,000 bytes and names every `ibr` subcommand (as `ibr NAME`);
ARCHITECTURE.md <= 15,000 bytes; neither holds a commit hash or a run-history
phrase; the guides and at least six decision records exist; no comment outside
tests/ and bench/ quotes a timing (figures go to the report and docs/decisions/).

usage: docs_rules.py SOURCE_DIR IBR_BINARY
"""
import os
import re
import subprocess
import sys

GUIDES = ["scene-format.md", "volumes.md", "deformations.md", "importing.md", "verify.md",
          "report.md", "glossary.md"]
HISTORY = re.compile(r"earlier runs?|run before|previous run|runs? earlier", re.I)
HASH = re.compile(r"\b[0-9a-f]{7,40}\b")
# A figure with a time unit or a speed ratio.
TIMING = re.compile(r"\b\d+(\.\d+)? ?(ms|fps|ns|µs)\b|\b\d+(\.\d+)?x (faster|slower)\b")
COMMENT = {".cc": "//", ".h": "//", ".glsl": "//", ".txt": "#", ".cmake": "#", ".py": "#",
           ".sh": "#"}


def subcommands(ibr):
    """`ibr NAME` and `ibr NAME SUB` for every subcommand, from the binary's own help."""
    def names(args):
        out = subprocess.run([ibr] + args + ["--help"], capture_output=True, text=True).stdout
        if "SUBCOMMANDS:" not in out and "Subcommands:" not in out:
            return []
        part = re.split(r"SUBCOMMANDS:|Subcommands:", out, maxsplit=1)[1]
        return [m.group(1) for m in re.finditer(r"^  (\S+)", part, re.M)]
    result = []
    for name in names([]):
        subs = names([name])
        result += [f"{name} {s}" for s in subs] if subs else [name]
    return result


def main():
    source, ibr = sys.argv[1], sys.argv[2]
    problems = []
    readme = open(os.path.join(source, "README.md")).read()
    arch = open(os.path.join(source, "ARCHITECTURE.md")).read()
    if len(readme.encode()) > 12000:
        problems.append(f"README.md is {len(readme.encode())} bytes (at most 12,000)")
    if len(arch.encode()) > 15000:
        problems.append(f"ARCHITECTURE.md is {len(arch.encode())} bytes (at most 15,000)")
    for name, text in (("README.md", readme), ("ARCHITECTURE.md", arch)):
        for m in HISTORY.finditer(text):
            problems.append(f"{name}: run-history phrase '{m.group(0)}'")
        for m in HASH.finditer(text):
            if re.search(r"[a-f]", m.group(0)) and re.search(r"\d", m.group(0)):
                problems.append(f"{name}: looks like a commit hash: {m.group(0)}")
    commands = subcommands(ibr)
    if len(commands) < 10:
        problems.append(f"only {len(commands)} subcommands found in `ibr --help`: {commands}")
    for c in commands:
        if f"ibr {c}" not in readme:
            problems.append(f"README.md does not name `ibr {c}`")
    for g in GUIDES:
        if not os.path.isfile(os.path.join(source, "docs", "guide", g)):
            problems.append(f"docs/guide/{g} is missing")
    decisions = [f for f in os.listdir(os.path.join(source, "docs", "decisions"))
                 if f.endswith(".md") and f != "README.md"]
    if len(decisions) < 6:
        problems.append(f"docs/decisions/ holds {len(decisions)} records (at least 6)")
    for top in ("core", "capture", "scene", "render", "shaders", "ibr", "apps", "datasets",
                "fuzz", "scripts", "cmake"):
        for root, _, files in os.walk(os.path.join(source, top)):
            for f in files:
                ext = os.path.splitext(f)[1] if f != "CMakeLists.txt" else ".txt"
                marker = COMMENT.get(ext)
                if marker is None:
                    continue
                path = os.path.join(root, f)
                for n, line in enumerate(open(path, errors="replace"), 1):
                    at = line.find(marker)
                    if at >= 0 and TIMING.search(line[at:]):
                        rel = os.path.relpath(path, source)
                        problems.append(f"{rel}:{n}: a comment quotes a timing: {line.strip()}")
    for p in problems:
        print(p)
    print(f"{0 if problems else 1} passed, {1 if problems else 0} failed")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
