#!/usr/bin/env python3
"""scripts/scene_format.py NARVAL [--check]: docs/scene-format.md's key tables from the loader.

Every table row whose first cell is a backticked key gets its type, req, default and range cells
from `NARVAL scene --keys` (the loader's own key table); the last cell, the key's meaning, is kept as
written. Without --check the file is rewritten; with --check nothing is written and the exit code is
1 when the file is not current (a key the loader reads is not documented, a documented key is not
read, a key has no meaning, or a generated cell differs), naming each finding on one line."""
import json
import pathlib
import re
import subprocess
import sys

DOC = pathlib.Path(__file__).resolve().parent.parent / "docs" / "scene-format.md"
HEADER = "| key | type | req | default | range | meaning |"
RULE = "|---|---|---|---|---|---|"
KEY_ROW = re.compile(r"^\|\s*`([^`]+)`\s*\|")


def cells(line):
    # Split a table row on pipes that are not inside backticks.
    out, cur, code = [], "", False
    for c in line.strip()[1:-1]:
        if c == "`":
            code = not code
        if c == "|" and not code:
            out.append(cur.strip())
            cur = ""
        else:
            cur += c
    out.append(cur.strip())
    return out


def row(key, k, meaning):
    defaults = " or ".join("`" + json.dumps(d) + "`" for d in k["defaults"])
    rng = k["range"].replace("|", "\\|")
    return "| `%s` | %s | %s | %s | %s | %s |" % (key, k["type"], "yes" if k["required"] else "",
                                                  defaults, rng, meaning)


def main():
    if len(sys.argv) < 2 or sys.argv[1].startswith("-"):
        sys.exit("usage: scripts/scene_format.py NARVAL [--check]")
    check = "--check" in sys.argv[2:]
    table = {k["key"]: k for k in json.loads(subprocess.check_output([sys.argv[1], "scene", "--keys"]))}
    text = DOC.read_text()
    lines, findings, documented = [], [], set()
    for line in text.splitlines():
        m = KEY_ROW.match(line)
        if line.startswith("| key |"):
            line = HEADER
        elif re.fullmatch(r"\|(-+\|)+", line.strip()) and lines and lines[-1] == HEADER:
            line = RULE
        elif m:
            key = m.group(1)
            documented.add(key)
            meaning = cells(line)[-1]
            if not meaning:
                findings.append("%s: no meaning written" % key)
            if key in table:
                line = row(key, table[key], meaning)
            else:
                findings.append("%s: documented, but the loader does not read it" % key)
        lines.append(line)
    for key in sorted(set(table) - documented):
        findings.append("%s: the loader reads it, but docs/scene-format.md does not document it" % key)
    new = "\n".join(lines) + "\n"
    if check:
        if new != text:
            findings.append("generated cells differ: run scripts/scene_format.py build/narval")
        for f in findings:
            print("docs/scene-format.md: " + f)
        sys.exit(1 if findings else 0)
    DOC.write_text(new)
    for f in findings:
        print("docs/scene-format.md: " + f)
    sys.exit(1 if findings else 0)


main()
