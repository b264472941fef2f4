"""Run every ```sh and ```python block of README.md and of every docs/ page (in DOCS_ORDER: a
page that uses another's outputs comes after it), then every command's examples from
`viewsynth <command> --help`, in order, in one scratch folder laid out as the README assumes (the
repository root, with ../shared/data beside it), and check every output line a block states.
Called by ci/readme-examples.sh; see there for the environment it needs.

A stated output is a line `# => TEXT` in a block: some line of that block's output (stdout and
stderr together) must hold TEXT, runs of spaces compared as one, `...` standing for any text in
between. So a stale figure in the README fails here.

A few commands stand for work .ci/run has already done, or cannot do here; each is replaced by
a check, or skipped, and said so (never silently):
  - `cargo install ... --path cli`: the `viewsynth` on PATH is .ci/run's target/release/viewsynth;
  - `cargo test --release`: .ci/run ran it before this script;
  - `pip install ... ./python[EXTRAS]`: ci/python-tests.sh installed the package into its venv,
    whose python is the one on PATH here; checked by importing the package and each extra;
  - `docker ...`: ci/docker-smoke.sh builds and runs the image (not part of .ci/run);
  - `cargo install cargo-fuzz ...`: needs a nightly toolchain.
"""

import os
import re
import subprocess
import sys
import time

# (pattern of a whole logical line, replacement or None to skip, why)
SUBSTITUTIONS = [
    (
        re.compile(r"cargo install (--locked )?--path cli(\s+#.*)?"),
        '"$VIEWSYNTH_BIN" --version',
        "the `viewsynth` on PATH is the one .ci/run's `cargo test --release` built (target/release)",
    ),
    (
        re.compile(r"cargo test --release(\s+#.*)?"),
        "true",
        ".ci/run runs it before this script",
    ),
    (
        re.compile(r"pip install (-v )?\"?\./python(\[(?P<extras>[a-z,]+)\])?\"?(\s+#.*)?"),
        "IMPORT",
        "ci/python-tests.sh installed ./python (and the extras' packages) into the venv on PATH",
    ),
    (
        re.compile(r"python3 -m venv \.venv && \. \.venv/bin/activate(\s+#.*)?"),
        "true",
        "the venv is ci/python-tests.sh's, already on PATH",
    ),
    (re.compile(r"docker .*"), None, "ci/docker-smoke.sh builds and runs the image (not in .ci/run)"),
    (re.compile(r"cargo install cargo-fuzz .*"), None, "cargo-fuzz needs a nightly toolchain"),
]

# What `import` proves each extra of python/pyproject.toml is there.
EXTRA_MODULES = {"examples": ["PIL"], "ray": ["ray", "ray.data"]}


def blocks(readme):
    """(kind, first line number, text) of every ```sh and ```python block."""
    out, kind, start, lines = [], None, 0, []
    for n, line in enumerate(readme.splitlines(), 1):
        if kind is None:
            m = re.match(r"^```(sh|python)\s*$", line)
            if m:
                kind, start, lines = m.group(1), n + 1, []
        elif line.startswith("```"):
            out.append((kind, start, "\n".join(lines) + "\n"))
            kind = None
        else:
            lines.append(line)
    if kind is not None:
        sys.exit(f"readme-examples: line {start}: a ```{kind} block is never closed")
    return out


def expectations(text):
    return [m.group(1).strip() for m in re.finditer(r"^\s*# => (.*)$", text, re.M)]


def logical_lines(text):
    """Lines with backslash continuations joined (heredoc bodies pass through as they are)."""
    out, cur = [], ""
    for line in text.splitlines():
        if line.endswith("\\"):
            cur += line[:-1] + " "
        else:
            out.append(cur + line)
            cur = ""
    if cur:
        out.append(cur)
    return out


def substitute(text, where, notes):
    """The block with the commands of SUBSTITUTIONS replaced, each replacement noted."""
    out = []
    for line in logical_lines(text):
        stripped = line.strip()
        for pattern, replacement, why in SUBSTITUTIONS:
            m = pattern.fullmatch(stripped)
            if not m:
                continue
            if replacement == "IMPORT":
                modules = ["viewsynth"]
                for extra in filter(None, (m.group("extras") or "").split(",")):
                    if extra not in EXTRA_MODULES:
                        sys.exit(f"readme-examples: {where}: unknown extra '{extra}' in: {stripped}")
                    modules += EXTRA_MODULES[extra]
                replacement = 'python -c "import ' + ", ".join(modules) + '"'
            notes.append(f"{where}: `{stripped}` -> " + (f"`{replacement}`" if replacement else "not run") + f": {why}")
            line = replacement if replacement is not None else ": skipped"
            break
        out.append(line)
    return "\n".join(out) + "\n"


def found(expected, output):
    squash = lambda s: re.sub(r"\s+", " ", s).strip()
    parts = [squash(p) for p in expected.split("...")]
    for line in output.splitlines():
        line, at = squash(line), 0
        for p in parts:
            i = line.find(p, at)
            if i < 0:
                break
            at = i + len(p)
        else:
            return True
    return False


# The docs/ pages in the order their examples run (after README.md): a page that reads another
# page's outputs (out/scene, out/cones, ...) comes after it. Every page must be listed.
DOCS_ORDER = ["scene", "refocus", "cyclopean", "compare", "reproject", "stereo", "stitch", "demo", "report",
              "bench", "stress", "info", "python", "docker", "formats", "internals"]

# The order of the commands whose `--help` examples run last, and the files the examples name
# as a user's own (a manifest), written into the scratch repository first.
HELP_ORDER = ["scene", "cyclopean", "compare", "refocus", "index", "manifest", "reproject", "stitch", "info",
              "bench", "stress", "report", "demo"]
HELP_FIXTURES = {
    # Four rows (one TUM frame under four names): `refocus --help` renders one shard of four, and
    # a shard count above the manifest's frame count is refused.
    "frames.csv": "rgb,depth,fx,fy,cx,cy,name\n" + "".join(
        "../shared/data/rgbd_open3d_testdata/TUM_color.png,../shared/data/rgbd_open3d_testdata/TUM_depth.png,"
        f"525,525,319.5,239.5,tum{k}\n" for k in range(4)),
    # A TUM-style sequence for `manifest --help`: its one frame, listed by timestamp.
    "tum_seq/rgb.txt": "# color images\n1305031102.175304 ../../shared/data/rgbd_open3d_testdata/TUM_color.png\n",
    "tum_seq/depth.txt": "# depth maps\n1305031102.160407 ../../shared/data/rgbd_open3d_testdata/TUM_depth.png\n",
}


def pages(readme_path):
    """(name, text) of README.md and every docs/ page, in the order they run."""
    docs = os.path.join(os.path.dirname(os.path.abspath(readme_path)), "docs")
    found = sorted(f[:-3] for f in os.listdir(docs) if f.endswith(".md"))
    missing = [f for f in found if f not in DOCS_ORDER]
    if missing:
        sys.exit(f"readme-examples: docs/{missing[0]}.md is not in DOCS_ORDER: its examples would not run")
    out = [("README.md", open(readme_path, encoding="utf-8").read())]
    for name in DOCS_ORDER:
        out.append((f"docs/{name}.md", open(os.path.join(docs, name + ".md"), encoding="utf-8").read()))
    return out


def help_examples():
    """(name, text) of each command's `--help` examples, as one ```sh block each."""
    listed = subprocess.run(["viewsynth", "--help"], stdout=subprocess.PIPE, check=True).stdout.decode()
    commands = re.findall(r"^  ([a-z]+)\s", listed.split("Commands:")[1].split("Options:")[0], re.M)
    commands = [c for c in commands if c != "help"]
    unordered = [c for c in commands if c not in HELP_ORDER]
    if unordered:
        sys.exit(f"readme-examples: command '{unordered[0]}' is not in HELP_ORDER: its --help examples would not run")
    out = []
    for c in HELP_ORDER:
        text = subprocess.run(["viewsynth", c, "--help"], stdout=subprocess.PIPE, check=True).stdout.decode()
        if "Examples:" not in text:
            sys.exit(f"readme-examples: `viewsynth {c} --help` shows no examples")
        lines = text.split("Examples:", 1)[1].strip("\n").splitlines()
        out.append((f"viewsynth {c} --help", "```sh\n" + "\n".join(l[2:] for l in lines) + "\n```\n"))
    return out


def main():
    readme_path, scratch = sys.argv[1], sys.argv[2]
    repo = os.path.join(scratch, "repo")
    for name, text in HELP_FIXTURES.items():
        os.makedirs(os.path.dirname(os.path.join(repo, name)), exist_ok=True)
        with open(os.path.join(repo, name), "w", encoding="utf-8") as f:
            f.write(text)
    # By hand: a third argument runs only the pages whose name holds it (e.g. "compare").
    only = sys.argv[3] if len(sys.argv) > 3 else ""
    all_blocks = [(page, kind, line, text) for page, doc in pages(readme_path) + help_examples()
                  for kind, line, text in blocks(doc) if only in page]
    notes, failures, checked = [], [], 0
    t_all = time.time()
    for i, (page, kind, line, text) in enumerate(all_blocks, 1):
        where = f"{page}:{line} ({kind} block {i} of {len(all_blocks)})"
        if kind == "sh":
            script = substitute(text, where, notes)
            cmd = ["bash", "-eo", "pipefail", "-c", script]
        else:
            path = os.path.join(scratch, f"block{i}.py")
            with open(path, "w", encoding="utf-8") as f:
                f.write(text)
            cmd = ["python", path]
        print(f"--- {where}", flush=True)
        t0 = time.time()
        try:
            r = subprocess.run(cmd, cwd=repo, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=900)
            output, status = r.stdout.decode("utf-8", "replace"), r.returncode
        except subprocess.TimeoutExpired as e:
            output, status = (e.stdout or b"").decode("utf-8", "replace"), "timeout (900 s)"
        shown = output.splitlines()
        if len(shown) > 40:
            shown = shown[:10] + [f"[... {len(shown) - 30} lines ...]"] + shown[-20:]
        print("\n".join("    " + s for s in shown))
        print(f"    ({time.time() - t0:.1f} s, exit {status})", flush=True)
        if status != 0:
            failures.append(f"{where}: exit {status}")
            continue
        for e in expectations(text):
            checked += 1
            if not found(e, output):
                failures.append(f"{where}: stated output not printed: {e}")
    print(f"\nreadme-examples: {len(all_blocks)} blocks run, {checked} stated outputs checked, "
          f"{time.time() - t_all:.0f} s")
    for n in notes:
        print(f"readme-examples: substituted {n}")
    if failures:
        print("\nreadme-examples: FAILED", file=sys.stderr)
        for f in failures:
            print(f"  {f}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
