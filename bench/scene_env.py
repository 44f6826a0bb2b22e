"""bench/scene_env.py: what the bench scripts share about narval's scene files."""
import os
import re


def expand_environment(text):
    """${NAME} and ${NAME:-default} (nested), as narval's scene loader expands volume paths."""
    out = ""
    i = 0
    while i < len(text):
        if not text.startswith("${", i):
            out += text[i]
            i += 1
            continue
        depth, j = 1, i + 2
        while j < len(text) and depth > 0:
            if text.startswith("${", j):
                depth += 1
                j += 2
                continue
            if text[j] == "}":
                depth -= 1
            j += 1
        if depth:
            raise ValueError("unterminated ${ in '%s'" % text)
        body = text[i + 2:j - 1]
        m = re.match(r"[A-Za-z_][A-Za-z0-9_]*", body)
        if not m:
            raise ValueError("bad variable reference ${%s}" % body)
        name, rest = m.group(0), body[m.end():]
        if rest and not rest.startswith(":-"):
            raise ValueError("bad variable reference ${%s}" % body)
        if os.environ.get(name):
            out += os.environ[name]
        elif rest:
            out += expand_environment(rest[2:])
        else:
            raise ValueError("environment variable %s is not set" % name)
        i = j
    return out
