#!/usr/bin/env python3
"""Regenerates the sample outputs in README.md from the real commands.

Each sample output is a fenced block right after a marker line
    <!-- output of: build/rtcost ARGS [| first N lines] -->
The command is run from the repository root and the block is replaced by what it prints (the
first N lines when asked, then a line "..." if there was more). Run after building:
    python3 scripts/readme-outputs.py
"""
import os
import re
import shlex
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MARKER = re.compile(r"^<!-- output of: (.*?)(?: \| first (\d+) lines)? -->$")


def main():
    path = os.path.join(ROOT, "README.md")
    lines = open(path).read().split("\n")
    out, i, done = [], 0, 0
    while i < len(lines):
        m = MARKER.match(lines[i])
        out.append(lines[i])
        i += 1
        if not m:
            continue
        cmd, first = m.group(1), m.group(2)
        if i >= len(lines) or not lines[i].startswith("```"):
            sys.exit(f"README.md:{i}: a marker must be followed by a fenced block")
        fence = lines[i]
        end = i + 1
        while end < len(lines) and not lines[end].startswith("```"):
            end += 1
        print(f"running {cmd}", file=sys.stderr)
        res = subprocess.run(shlex.split(cmd), cwd=ROOT, capture_output=True, text=True)
        if res.returncode != 0:
            sys.exit(f"{cmd}: exit {res.returncode}\n{res.stderr}")
        text = res.stdout.rstrip("\n").split("\n")
        if first and len(text) > int(first):
            text = text[: int(first)] + ["..."]
        out += [fence] + text + ["```"]
        i = end + 1
        done += 1
    with open(path + ".tmp", "w") as f:
        f.write("\n".join(out))
    os.replace(path + ".tmp", path)
    print(f"README.md: {done} sample outputs regenerated", file=sys.stderr)


if __name__ == "__main__":
    main()
