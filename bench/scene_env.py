"""bench/scene_env.py: what the bench scripts share: running narval, and scenes as narval reads them.

Scene values come from narval itself (`narval scene SCENE --set ... --resolved`, `narval scene
--keys`): a bench script never restates one of narval's defaults. From a shell:
  python3 bench/scene_env.py get NARVAL SCENE KEY [--set PATH=VALUE ...]   one resolved value (JSON)
  python3 bench/scene_env.py volumes SCENE                               the scene's volume files
  python3 bench/scene_env.py missing SCENE                               those of them that are absent
"""
import json
import os
import re
import subprocess
import sys
from pathlib import Path


class NarvalError(RuntimeError):
    """A narval command failed; the message carries the command and its stderr."""


def run_narval(narval, args, cwd=None):
    """Runs narval with the arguments; returns stdout; raises NarvalError with stderr on failure."""
    command = [str(narval)] + [str(a) for a in args]
    done = subprocess.run(command, cwd=cwd, capture_output=True, text=True)
    if done.returncode != 0:
        raise NarvalError("%s (exit %d): %s" % (" ".join(command), done.returncode, done.stderr.strip()))
    return done.stdout


def run_json(narval, args, cwd=None):
    """run_narval's stdout parsed as JSON (compare --json, devices --json, scene --resolved)."""
    return json.loads(run_narval(narval, args, cwd))


def resolved_scene(narval, scene_path, sets=()):
    """The scene as narval renders it, every default the loader took written out: `narval scene
    SCENE --set S ... --resolved`, parsed. sets: PATH=VALUE strings, as render's --set takes them."""
    return run_json(narval, ["scene", scene_path] + [a for s in sets for a in ("--set", s)] + ["--resolved"])


def key_table(narval):
    """`narval scene --keys` as {key: entry}; entry["defaults"] lists the loader's default(s)."""
    return {k["key"]: k for k in run_json(narval, ["scene", "--keys"])}


def value_at(data, dotted):
    """data["msCache"]["resolution"] for 'msCache.resolution'; KeyError when a level is absent."""
    for key in dotted.split("."):
        data = data[int(key) if isinstance(data, list) else key]
    return data


def expand_environment(text):
    """${NAME} and ${NAME:-default} (nested), as narval's scene loader expands volume paths."""
    out, i = "", 0
    while i < len(text):
        if not text.startswith("${", i):
            out += text[i]
            i += 1
            continue
        depth, j = 1, i + 2
        while j < len(text) and depth > 0:
            if text.startswith("${", j):
                depth, j = depth + 1, j + 2
                continue
            depth -= text[j] == "}"
            j += 1
        if depth:
            raise ValueError("unterminated ${ in '%s'" % text)
        m = re.fullmatch(r"([A-Za-z_][A-Za-z0-9_]*)(:-(.*))?", text[i + 2:j - 1], re.S)
        if not m:
            raise ValueError("bad variable reference ${%s}" % text[i + 2:j - 1])
        if os.environ.get(m.group(1)):
            out += os.environ[m.group(1)]
        elif m.group(2) is not None:
            out += expand_environment(m.group(3))
        else:
            raise ValueError("environment variable %s is not set" % m.group(1))
        i = j
    return out


def volume_path(scene_path, path):
    """A material's volume path as the loader finds it: expanded, relative to the scene's folder."""
    p = Path(expand_environment(path))
    return Path(os.path.normpath(p if p.is_absolute() else Path(scene_path).resolve().parent / p))


def volume_files(scene_path):
    """The scene's volume files as text: paths as the loader finds them, or the path written and why
    it cannot be expanded."""
    files = []
    with open(scene_path) as f:
        materials = json.load(f).get("materials", [])
    for m in materials:
        if m.get("type") == "volume" and isinstance(m.get("path"), str):
            try:
                files.append(str(volume_path(scene_path, m["path"])))
            except ValueError as e:
                files.append("%s (%s)" % (m["path"], e))
    return files


def missing_volumes(scene_path):
    """The scene's volume files that are absent (or whose path cannot be expanded), as text."""
    return [f for f in volume_files(scene_path) if not os.path.isfile(f)]


def main(argv):
    if len(argv) >= 4 and argv[0] == "get":
        sets = [s for flag, s in zip(argv[4::2], argv[5::2]) if flag == "--set"]
        print(json.dumps(value_at(resolved_scene(argv[1], argv[2], sets), argv[3])))
        return 0
    if len(argv) == 2 and argv[0] in ("volumes", "missing"):
        for path in (volume_files if argv[0] == "volumes" else missing_volumes)(argv[1]):
            print(path)
        return 0
    print(__doc__.strip().split("\n\n")[1], file=sys.stderr)
    return 2


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv[1:]))
    except NarvalError as e:
        sys.exit("scene_env: %s" % e)
