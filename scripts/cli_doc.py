#!/usr/bin/env python3
"""scripts/cli_doc.py NARVAL: checks that docs/cli.md documents every command and every flag.

The commands and their flags come from the parser itself (`NARVAL --help` and `NARVAL COMMAND --help`,
CLI11's listing); each flag must appear in backticks in its command's section (`## narval COMMAND`)
of docs/cli.md. Prints one line per finding; exit code 1 when there is any."""
import pathlib
import re
import subprocess
import sys

DOC = pathlib.Path(__file__).resolve().parent.parent / "docs" / "cli.md"


def help_text(narval, *command):
    return subprocess.run([narval, *command, "--help"], capture_output=True, text=True, check=True).stdout


def flags(text):
    # Option lines of CLI11's listing: "  -o,--output TEXT   ..." or "  --quiet   ...".
    found = []
    for line in text.split("Options:", 1)[-1].splitlines():
        m = re.match(r"^\s+((?:-{1,2}[\w-]+,?)+)", line)
        if m:
            found += [f for f in m.group(1).split(",") if f and f not in ("-h", "--help")]
    return found


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: scripts/cli_doc.py NARVAL")
    narval = sys.argv[1]
    top = help_text(narval)
    commands = re.findall(r"^  ([a-z][\w-]*)\s", top.split("Subcommands:", 1)[1], re.M)
    sections = {}
    for part in re.split(r"^## ", DOC.read_text(), flags=re.M)[1:]:
        title, _, body = part.partition("\n")
        sections[title.strip()] = body
    findings = []
    for f in flags(top):
        if "`%s`" % f not in DOC.read_text():
            findings.append("narval %s: not documented" % f)
    for c in commands:
        body = sections.get("narval " + c)
        if body is None:
            findings.append("narval %s: no section '## narval %s'" % (c, c))
            continue
        for f in flags(help_text(narval, c)):
            if "`%s" % f not in body:
                findings.append("narval %s %s: not documented in its section" % (c, f))
    for f in findings:
        print("docs/cli.md: " + f)
    if not commands:
        findings.append("no commands found in `narval --help`")
        print("docs/cli.md: no commands found in `narval --help`")
    sys.exit(1 if findings else 0)


main()
