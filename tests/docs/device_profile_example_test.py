#!/usr/bin/env python3
"""docs/device-profile.md, "Bringing up a new drive", kept true to its files and commands.

In that section every ```json block is preceded by a marker saying what it is:
  <!-- file: PATH -->     the block is the file PATH (repository-relative), equal as JSON;
  <!-- part of: PATH -->  every key the block has, the file has with the same value (objects
                          compared key by key, recursively; anything else must be equal).
A ``` block preceded by <!-- output checked --> starts with "$ synbench ARGS": the command is
run from the repository's root and must print exactly the block's other lines (the probe and the
point need a running emulator and are not rerun here). Every profile a block names must pass
`synbench profile check`, every bench config `synbench bench check`.
Usage: device_profile_example_test.py SYNBENCH_BINARY SOURCE_DIR"""
import json
import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "server"))
from checks import Checks  # noqa: E402

BIN, ROOT = sys.argv[1], sys.argv[2]
DOC = os.path.join(ROOT, "docs", "device-profile.md")
SECTION = "## Bringing up a new drive"
check = Checks(verbose=True)


def section(text):
    start = text.find("\n" + SECTION)
    if start < 0:
        return ""
    end = text.find("\n## ", start + 1)
    return text[start:end if end > 0 else len(text)]


def blocks(text):
    """(marker or None, info string, body, line number) of every fenced block."""
    out = []
    lines = text.split("\n")
    i = 0
    while i < len(lines):
        m = re.match(r"^```(\w*)\s*$", lines[i])
        if not m:
            i += 1
            continue
        j = i - 1
        while j >= 0 and not lines[j].strip():
            j -= 1
        marker = lines[j].strip() if j >= 0 and lines[j].strip().startswith("<!--") else None
        k = i + 1
        while k < len(lines) and lines[k].strip() != "```":
            k += 1
        out.append((marker, m.group(1), "\n".join(lines[i + 1:k]), i + 1))
        i = k + 1
    return out


def is_part(part, whole, where=""):
    """The first key path where `part` differs from `whole`, or None."""
    if isinstance(part, dict):
        if not isinstance(whole, dict):
            return where or "/"
        for k, v in part.items():
            if k not in whole:
                return f"{where}/{k} (not in the file)"
            bad = is_part(v, whole[k], f"{where}/{k}")
            if bad:
                return bad
        return None
    return None if part == whole else (where or "/")


with open(DOC) as f:
    text = section(f.read())
check(bool(text), f"{DOC} has the section '{SECTION}'")
found = blocks(text)
named = set()
for marker, info, body, line in found:
    where = f"section line {line}"
    if info == "json":
        m = re.match(r"<!--\s*(file|part of):\s*(\S+)\s*-->", marker or "")
        if not check(m is not None, f"{where}: a json block says which file it is (<!-- file: PATH --> or <!-- part of: PATH -->)"):
            continue
        how, path = m.group(1), m.group(2)
        named.add(path)
        try:
            shown = json.loads(body)
        except ValueError as e:
            check(False, f"{where}: the block is JSON: {e}")
            continue
        try:
            with open(os.path.join(ROOT, path)) as f:
                actual = json.load(f)
        except (OSError, ValueError) as e:
            check(False, f"{where}: {path} reads as JSON: {e}")
            continue
        if how == "file":
            check(shown == actual, f"{where}: the block is {path} (equal as JSON)")
        else:
            bad = is_part(shown, actual)
            check(bad is None, f"{where}: the block is part of {path}" + (f": differs at {bad}" if bad else ""))
    elif marker and re.match(r"<!--\s*output checked\s*-->", marker):
        lines = body.split("\n")
        if not check(lines[0].startswith("$ synbench "), f"{where}: an output block starts with '$ synbench ...'"):
            continue
        args = lines[0][len("$ synbench "):].split()
        p = subprocess.run([BIN, *args], cwd=ROOT, capture_output=True, text=True, timeout=30)
        want = "\n".join(lines[1:]).rstrip()
        got = (p.stdout + p.stderr).rstrip()
        check(got == want, f"{where}: `{lines[0][2:]}` prints what the document shows:\n--- document\n{want}\n--- now\n{got}")

check("tests/server/vendor_bench/synrm_drive.json" in named and any(p.endswith("bench.json") for p in named),
      f"the example shows the SynRM drive's profile and its bench config: {sorted(named)}")
for path in sorted(named):
    with open(os.path.join(ROOT, path)) as f:
        doc = json.load(f)
    cmd = ["profile", "check", path] if "kind" in doc else ["bench", "check", path]
    p = subprocess.run([BIN, *cmd], cwd=ROOT, capture_output=True, text=True, timeout=30)
    check(p.returncode == 0 and ": ok" in p.stdout,
          f"synbench {' '.join(cmd)}: exit {p.returncode}: {(p.stdout + p.stderr).strip()[:300]}")
check.finish("the worked example matches its files and commands")
