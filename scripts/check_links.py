#!/usr/bin/env python3
"""Check that every repository path the documentation cites exists.

    python3 scripts/check_links.py [--root DIR] [FILE.md ...]
    python3 scripts/check_links.py --self-test

Without FILEs it reads README.md, CONTRIBUTING.md, results/README.md, docs/*.md and
studies/numerics/README.md. A cited path is a word starting with a top-level folder of the
repository (studies/, results/, docs/, scripts/, engine/, analysis/, study/, cli/, tests/,
bench/, fuzz/), in backticks, in a markdown link or in the prose, relative to the root; a
markdown link that is not one of those is resolved against the citing file's folder.
Placeholders (`results/<name>.db`, `…/NAME/…`, `case_NNN_…`) and what a command writes (after
--out, --csv, --views) are skipped, `{a,b}` is expanded, `*` must match at least one file, a
stem (`analysis/plot`) may stand for its files and a `:line` suffix is dropped. In a git work
tree a path must be tracked, as a fresh clone would have it. Prints each missing path with file and line and exits 1
if there is any. --self-test checks the checker on a generated file with one dangling path.
"""
import argparse
import fnmatch
import glob
import os
import re
import subprocess
import sys
import tempfile

FOLDERS = ("studies", "results", "docs", "scripts", "engine", "analysis", "study", "cli",
           "tests", "bench", "fuzz")
# A folder name at the start of a word (not inside another path such as ./build/cli/crevasse).
PATH = re.compile(r"(?<![\w./\-…])(?:%s)/[^\s`'\"()\[\]<>;|]*" % "|".join(FOLDERS))
LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")
PLACEHOLDER = re.compile(r"<|…|\.\.\.|NNN|(?:^|/)[A-Z][A-Z0-9_]+(?:/|\.|$)")


def expand_braces(path):
    m = re.search(r"\{([^{}]*)\}", path)
    if not m:
        return [path]
    out = []
    for alt in m.group(1).split(","):
        out += expand_braces(path[:m.start()] + alt + path[m.end():])
    return out


def tracked_files(root):
    """The files git tracks under root, or None outside a work tree: a path that exists only in
    this working copy (kept particles, a local database) would be missing from a fresh clone."""
    try:
        out = subprocess.run(["git", "-C", root, "ls-files", "-z"], capture_output=True,
                             check=True).stdout.decode("utf-8")
    except (OSError, subprocess.CalledProcessError):
        return None
    files = set(f for f in out.split("\0") if f)
    if not files:
        return None
    dirs = set()
    for f in files:
        d = os.path.dirname(f)
        while d and d not in dirs:
            dirs.add(d)
            d = os.path.dirname(d)
    return files | dirs


def exists(root, path, tracked=None):
    if tracked is not None:
        p = os.path.normpath(path)
        if "*" in p:
            return any(fnmatch.fnmatchcase(f, p) for f in tracked)
        return p in tracked or any(f.startswith(p + ".") and "/" not in f[len(p):] for f in tracked)
    full = os.path.join(root, path)
    if "*" in path:
        return bool(glob.glob(full))
    # A source module may be cited by its stem (`analysis/plot` for plot.hpp and plot.cpp).
    return os.path.exists(full) or bool(glob.glob(glob.escape(full) + ".*"))


def cited_paths(text):
    """(line number, path) of every repository path the markdown text cites."""
    for n, line in enumerate(text.splitlines(), 1):
        for m in PATH.finditer(line):
            path = re.sub(r"(:\d+)+$", "", m.group(0).rstrip(".,:;!?"))  # file.cpp:114:14
            if PLACEHOLDER.search(path) or path.count("{") != path.count("}"):
                continue
            if re.search(r"--(?:out|csv|views)\s+$", line[:m.start()]):
                continue  # a file the command writes
            for p in expand_braces(path):
                yield n, p, False
        for m in LINK.finditer(line):
            target = m.group(1).split("#")[0]
            if not target or re.match(r"[a-z]+:", target) or target.split("/")[0] in FOLDERS:
                continue  # a web address, an anchor, or a root path already checked above
            yield n, target, True


def check(root, files):
    tracked = tracked_files(root)
    missing = []
    for f in files:
        with open(os.path.join(root, f), encoding="utf-8") as fh:
            text = fh.read()
        for n, path, relative in cited_paths(text):
            p = os.path.normpath(os.path.join(os.path.dirname(f), path)) if relative else path
            if not exists(root, p, tracked):
                missing.append(f"{f}:{n}: {path}")
    return missing


def default_files(root):
    files = ["README.md", "CONTRIBUTING.md", "results/README.md", "studies/numerics/README.md"]
    files = [f for f in files if os.path.exists(os.path.join(root, f))]
    return files + sorted(os.path.relpath(p, root) for p in glob.glob(os.path.join(root, "docs/*.md")))


def self_test():
    """The checker reports a dangling path and nothing else on a file citing good ones too."""
    with tempfile.TemporaryDirectory() as root:
        os.makedirs(os.path.join(root, "docs"))
        os.makedirs(os.path.join(root, "results/numerics"))
        for f in ("docs/model.md", "results/numerics/a.db", "results/numerics/b.db"):
            open(os.path.join(root, f), "w").close()
        with open(os.path.join(root, "docs/test.md"), "w", encoding="utf-8") as fh:
            fh.write("See `docs/model.md`, [the model](model.md), results/numerics/{a,b}.db,\n"
                     "`results/<name>.db` and `crevasse study studies/gone.json --db …`.\n"
                     "[missing](../results/lost.db)\n")
        got = check(root, ["docs/test.md"])
        # In a git work tree a file git does not track counts as missing: a fresh clone lacks it.
        tracked_case = subprocess.run(["git", "init", "-q", root], capture_output=True).returncode == 0
        if tracked_case:
            subprocess.run(["git", "-C", root, "add", "docs", "results/numerics/a.db"], check=True)
            got_tracked = check(root, ["docs/test.md"])
    want = ["docs/test.md:2: studies/gone.json", "docs/test.md:3: ../results/lost.db"]
    if got != want:
        print(f"self-test failed: reported {got}, expected {want}")
        return 1
    want_tracked = ["docs/test.md:1: results/numerics/b.db"] + want
    if tracked_case and got_tracked != want_tracked:
        print(f"self-test failed in a git work tree: reported {got_tracked}, expected {want_tracked}")
        return 1
    print("self-test passed: the dangling paths are reported, the others are not")
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("files", nargs="*", help="markdown files relative to the root")
    ap.add_argument("--root", default=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    ap.add_argument("--self-test", action="store_true")
    args = ap.parse_args()
    if args.self_test:
        return self_test()
    files = args.files or default_files(args.root)
    missing = check(args.root, files)
    for m in missing:
        print(f"missing: {m}")
    print(f"{len(files)} files checked, {len(missing)} missing paths")
    return 1 if missing else 0


if __name__ == "__main__":
    sys.exit(main())
