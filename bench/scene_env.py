"""bench/scene_env.py: what the bench scripts share: running narval, scenes as narval reads them (a
script never restates a narval default: `narval scene --resolved`, `--keys`), options, renders and their
--stats-json, `narval compare`, references kept between runs, alternating repetitions, Markdown tables,
pictures (montage). `python3 bench/scene_env.py volumes SCENE` prints the scene's volume files, one a line."""
import argparse
import atexit
import json
import os
import re
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
# `narval compare` without a display transform (linear values clipped to [0, 1]): what the tables
# recorded before compare took the scene's transform from the EXRs by default.
LINEAR = ("--tonemap", "none", "--exposure", "0")
# The ray marcher as the dissertation's single-scattering march (its multiple-scattering cache is the default).
MARCH = 'renderer.raymarch.multipleScattering="none"'


class NarvalError(RuntimeError):
    """A narval command failed; the message carries the command and its stderr."""


def run_narval(narval, args, cwd=None, env=None):
    """Runs narval with the arguments; returns stdout; raises NarvalError with stderr on failure."""
    command = [str(narval)] + [str(a) for a in args]
    done = subprocess.run(command, cwd=cwd, env=env, capture_output=True, text=True)
    if done.returncode != 0:
        raise NarvalError("%s (exit %d): %s" % (" ".join(command), done.returncode, done.stderr.strip()))
    return done.stdout


def run_json(narval, args, cwd=None):
    """run_narval's stdout parsed as JSON."""
    return json.loads(run_narval(narval, args, cwd))


def resolved_scene(narval, scene_path, sets=()):
    """The scene as narval renders it, every default written out: `narval scene SCENE --set S ...
    --resolved`, parsed (sets: PATH=VALUE strings)."""
    return run_json(narval, ["scene", scene_path] + [a for s in sets for a in ("--set", s)] + ["--resolved"])


def key_table(narval):
    """`narval scene --keys` as {key: entry}; entry["defaults"] lists the loader's default(s)."""
    return {k["key"]: k for k in run_json(narval, ["scene", "--keys"])}


def expand_environment(text):
    """${NAME} and ${NAME:-default} (nested), as narval's scene loader expands volume paths."""
    def value(m):  # innermost first; an unset NAME without default is marked, an error unless discarded
        if os.environ.get(m.group(1)):
            return os.environ[m.group(1)]
        return "\0%s\0" % m.group(1) if m.group(2) is None else m.group(2)
    innermost = re.compile(r"\$\{([A-Za-z_][A-Za-z0-9_]*)(?::-([^${}]*))?\}")
    while innermost.search(text):
        text = innermost.sub(value, text)
    unset = re.search("\0(.*?)\0", text)
    if unset or "${" in text:
        raise ValueError("environment variable %s is not set" % unset.group(1) if unset
                         else "bad variable reference in '%s'" % text)
    return text


def volume_path(scene_path, path):
    """A material's volume path as the loader finds it: expanded, relative to the scene's folder."""
    p = Path(expand_environment(path))
    return Path(os.path.normpath(p if p.is_absolute() else Path(scene_path).resolve().parent / p))


def volume_files(scene_path):
    """The scene's volume files as the loader finds them (or the path and why it cannot be expanded)."""
    files = []
    for m in json.loads(Path(scene_path).read_text()).get("materials", []):
        if m.get("type") == "volume" and isinstance(m.get("path"), str):
            try:
                files.append(str(volume_path(scene_path, m["path"])))
            except ValueError as e:
                files.append("%s (%s)" % (m["path"], e))
    return files


def missing_volumes(scene_path):
    """What a scene lacks: the scene file when it is absent, else its volume files that are absent (or
    whose path cannot be expanded), as text."""
    if not os.path.isfile(scene_path):
        return [str(scene_path)]
    return [f for f in volume_files(scene_path) if not os.path.isfile(f)]


def parser(doc, device=True):
    """Options every script takes: --narval (default $NARVAL, else build/narval) and --device."""
    p = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--narval", default=os.environ.get("NARVAL", str(REPO / "build" / "narval")))
    if device:
        p.add_argument("--device", help="narval --device SPEC for every render")
    return p


def options(p, **defaults):
    """Adds an option --NAME (underscores as dashes) per keyword, of its default's type and value."""
    for name, default in defaults.items():
        p.add_argument("--" + name.replace("_", "-"), type=type(default), default=default)


def parse(p, argv=None):
    """Parsed options, run from the repository root with a scratch folder `work` (removed at exit)."""
    a = p.parse_args(argv)
    a.narval = str(Path(a.narval).resolve())
    if not os.access(a.narval, os.X_OK):
        p.error("no narval binary at %s (scripts/setup.sh builds it)" % a.narval)
    os.chdir(REPO)
    a.work = Path(tempfile.mkdtemp(prefix="narval_bench_"))
    atexit.register(shutil.rmtree, a.work, True)
    return a


def main(run):
    """Exits with run()'s result; a failed narval command or a missing file: one line on stderr, exit 1."""
    try:
        sys.exit(run())
    except (NarvalError, OSError) as e:
        sys.exit("%s: %s" % (Path(sys.argv[0]).name, e))


def render(a, scene, *options, out=None, env=None, sets=()):
    """`narval render SCENE OPTIONS --set SET...` on a.device into out (default: scratch); its stats."""
    out = Path(out or a.work / "out.exr")
    device = ["--device", a.device] if getattr(a, "device", None) else []
    run_narval(a.narval, ["render", scene, "-o", out, "--stats-json", out.with_suffix(".json")] + device
               + list(options) + [x for s in sets for x in ("--set", s)], env=env)
    return json.loads(out.with_suffix(".json").read_text())


def seconds(stats):
    """A render's time: the path tracer's kernel seconds, else the median kernel seconds per frame."""
    return stats["kernel_seconds"] if stats["algorithm"] == "pathtrace" else stats["ms_per_frame"]["median"] / 1e3


def compare(a, reference, test, *options):
    """`narval compare REFERENCE TEST --json`, parsed."""
    return run_json(a.narval, ["compare", reference, test, "--json"] + list(options))


FLIP_VENV, FLIP_PACKAGES = REPO / "build" / "flip-venv", ["flip-evaluator==1.7", "numpy"]


def flip(pairs):
    """Mean HDR-FLIP (flip-evaluator's default viewing conditions) of each (reference, test) pair of EXRs, in
    build/flip-venv, made on first use: FLIP is never a build or test dependency."""
    python = FLIP_VENV / "bin" / "python"
    if not python.exists():
        subprocess.run([sys.executable, "-m", "venv", str(FLIP_VENV)], check=True)
        subprocess.run([str(FLIP_VENV / "bin" / "pip"), "install", "-q", "--disable-pip-version-check"] + FLIP_PACKAGES,
                       check=True)
    script = ("import sys, flip_evaluator as f\n"
              "for r, t in zip(sys.argv[1::2], sys.argv[2::2]): print(f.evaluate(r, t, 'HDR')[1])")
    out = subprocess.run([str(python), "-c", script] + [str(p) for pair in pairs for p in pair], check=True,
                         capture_output=True, text=True)
    return [float(v) for v in out.stdout.split()]


def reference(a, scene, out, spp, *options, snapshot=None):
    """A path-traced reference at out, kept between runs: `narval render --resume` renders it when
    absent, completes an interrupted one, leaves a finished one as it is, and refuses one from other
    settings, which is then rendered again. With snapshot (a path), the first quarter of the samples
    is copied there before the rest is rendered (for `compare --reference-snapshot`). Its stats."""
    out, snapshot = Path(out), snapshot and Path(snapshot)
    args = [scene, "--algorithm", "pathtrace", *options]
    for attempt in range(2):
        try:
            if snapshot and not snapshot.is_file():
                out.unlink(missing_ok=True)
                render(a, *args, "--spp", max(1, spp // 4), "--resume", out=out)
                shutil.copyfile(out, snapshot)
            return render(a, *args, "--spp", spp, "--resume", out=out)
        except NarvalError as e:
            if attempt:
                raise
            print("  %s: rendering %s again" % (str(e).splitlines()[-1], out), file=sys.stderr)
            for f in filter(None, (out, snapshot)):
                f.unlink(missing_ok=True)


def alternate(reps, runs):
    """runs: {name: a function returning seconds}. One warm-up of each (program build, first launch),
    then reps repetitions running each in turn (A, B, A, B, ...) so that all see the same machine
    load. {name: [seconds of each repetition]}."""
    for run in runs.values():
        run()
    times = {name: [] for name in runs}
    for _ in range(reps):
        for name, run in runs.items():
            times[name].append(run())
    return times


def ab_cells(a, b, inverse=False):
    """[median A, median B, A/B, per-repetition A/B] of two lists of seconds (B/A with inverse)."""
    ma, mb = statistics.median(a), statistics.median(b)
    (n, m), pairs = ((mb, ma), zip(b, a)) if inverse else ((ma, mb), zip(a, b))
    return ["%.4f" % ma, "%.4f" % mb, "%.3f" % (n / m), ", ".join("%.3f" % (x / y) for x, y in pairs)]


def cpu_seconds():
    """User + system CPU seconds of this process's finished children so far (a difference around a
    render is its CPU time: PoCL runs the kernels on the process's own threads)."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def row(*cells):
    """One Markdown table row, printed at once (long runs show their rows as they come)."""
    print("| " + " | ".join(str(c) for c in cells) + " |", flush=True)


def header(*columns):
    row(*columns)
    print("|" + "---|" * len(columns))


def need_pillow(label):
    """PIL, before any work: Debian's python3-pil, installed if missing (scripts/apt_packages.sh: as root,
    else it prints the apt-get line and this exits); the script rerun by /usr/bin/python3 if still lacking."""
    try:
        import PIL  # noqa: F401
    except ImportError:
        install = '. scripts/apt_packages.sh && apt_install_missing "$0" python3-pil'
        if subprocess.run(["bash", "-c", install, label], cwd=REPO).returncode:
            sys.exit(2)
        if os.path.realpath(sys.executable) != os.path.realpath("/usr/bin/python3"):
            os.execv("/usr/bin/python3", ["/usr/bin/python3", os.path.abspath(sys.argv[0])] + sys.argv[1:])


def montage(rows, out, headers=(), gap=0):
    """Rows of tiles [(a PNG's path or an HxWx3 uint8 array, caption)] as one PNG at out, gap white pixels
    between the columns: the headers on a line over the columns, each caption on a line under its tile."""
    from PIL import Image, ImageDraw
    tiles = [[Image.fromarray(t) if hasattr(t, "shape") else Image.open(t).convert("RGB") for t, _ in r] for r in rows]
    w, h = tiles[0][-1].size
    if any(t.size != (w, h) for r in tiles for t in r):
        raise NarvalError("%s: tiles of other sizes than %dx%d" % (out, w, h))
    top, line = 16 if headers else 0, 16 if any(c for r in rows for _, c in r) else 0
    sheet = Image.new("RGB", (len(tiles[0]) * (w + gap) - gap, top + len(rows) * (h + line)), "white")
    draw = ImageDraw.Draw(sheet)
    for j, text in enumerate(headers):
        draw.text((j * (w + gap) + 4, 2), text, fill="black")
    for i, row in enumerate(rows):
        for j, (tile, (_, caption)) in enumerate(zip(tiles[i], row)):
            x, y = j * (w + gap), top + i * (h + line)
            sheet.paste(tile, (x, y))
            draw.text((x + 4, y + h + 2), caption, fill="black")
    sheet.save(out)
    print("wrote %s" % out)


def scene_name(path):
    return Path(path).stem


def load_average():
    return " ".join(Path("/proc/loadavg").read_text().split()[:3])


if __name__ == "__main__":
    if len(sys.argv) != 3 or sys.argv[1] != "volumes":
        sys.exit("usage: python3 bench/scene_env.py volumes SCENE")
    print("\n".join(volume_files(sys.argv[2])))
