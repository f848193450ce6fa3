#!/usr/bin/python3
"""Checks that the includes of splat's library sources run down its layers, never up.

The library (splat/src) is built in floors, lowest first; a file may include a header of
its own folder or of a folder on a lower floor, never one above, nor one on its own floor
(the renderers do not know each other) but for the one-way uses listed in SIBLING_USES:

  0  model, io,       the model: volume, settings, classification, splat list, Scene,
     options          transfer table, levels of detail; reading and writing files; the
                      option table and the parsers of option values into settings
  1  frame            the frame stages the renderers share: projection, binning to tiles,
                      the tile sweep, sheet buffers, compositing, per-frame workspaces
  2  splatters,       the renderers; each keeps its own per-scene state
     reference,       (Scene::Impl::state) and may use the shared stages
     gaussians
  3  dispatch         chooses the renderer (and level of detail) for a frame; Scene::render
  4  sequence         many frames of a Scene: camera paths, the frame farm, sort-last bricks
                      and their memory budget
  5  analysis         popping, study, metrics and reports over rendered frames

Below every floor: the footprint library (footprint/, its own target, which includes
nothing of splat) and the public headers (splat/include/splat: the library's interface,
declarations only, which include no internal header). Above every floor: the outer layers
(tools/cli, splat/python, splat/mpi), which splat/src never includes.

Usage: check_layers.py [REPO_ROOT]    exit 0 when every include runs down, else 1
       check_layers.py --self-test    checks that the check finds what it must (a back
                                      include, a sibling include, an unknown folder, a stale
                                      exception)
"""
import os
import re
import sys
import tempfile

FLOORS = [
    ("model", "io", "options"),
    ("frame",),
    ("splatters", "reference", "gaussians"),
    ("dispatch",),
    ("sequence",),
    ("analysis",),
]

# Includes that may run against the floors, as (including file, included header) relative
# to splat/src, each with why. At most MAX_EXCEPTIONS; every one must still occur (a stale
# entry fails, so the list only shrinks).
EXCEPTIONS = {
    # None: every include in splat/src runs down.
}
MAX_EXCEPTIONS = 4

# Folders on one floor that may use another's headers, one way, as (user, used): why.
SIBLING_USES = {
    ("gaussians", "splatters"): "Gaussian splats are splatted by the splatters' stages: the "
    "Splatter interface and their frame pipeline (splatters/splatter.h)",
}

INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)
SOURCE = (".h", ".hpp", ".cpp", ".cc", ".inl")


def floor_of(folder):
    for n, floor in enumerate(FLOORS):
        if folder in floor:
            return n
    return None


def sources(root):
    for dirpath, _, names in os.walk(root):
        for name in sorted(names):
            if name.endswith(SOURCE):
                yield os.path.join(dirpath, name)


def check(repo):
    """Returns the list of problems (one line each) in `repo`."""
    src = os.path.join(repo, "splat", "src")
    problems, seen = [], set()
    if not os.path.isdir(src):
        return ["no splat/src under " + repo]
    for path in sources(src):
        rel = os.path.relpath(path, src).replace(os.sep, "/")
        folder = rel.split("/")[0] if "/" in rel else ""
        own = floor_of(folder)
        if own is None:
            problems.append(f"splat/src/{rel}: folder '{folder}' is on no floor (add it to "
                            "FLOORS in tests/layers/check_layers.py)")
            continue
        with open(path, encoding="utf-8", errors="replace") as f:
            text = f.read()
        for header in INCLUDE.findall(text):
            if header.startswith(("splat/", "footprint/")):
                continue  # the public interface and the footprint library: below every floor
            target = header if "/" in header else f"{folder}/{header}"
            to = target.split("/")[0]
            if not os.path.exists(os.path.join(src, target)):
                problems.append(f"splat/src/{rel}: includes \"{header}\", which is not in "
                                "splat/src (the outer layers are never included)")
                continue
            up = floor_of(to)
            if to == folder or (up is not None and up < own) or (folder, to) in SIBLING_USES:
                continue
            if (rel, target) in EXCEPTIONS:
                seen.add((rel, target))
                continue
            how = "a sibling on its own floor" if up == own else f"floor {up}, above its {own}"
            problems.append(f"splat/src/{rel}: includes \"{target}\" ({to}/ is {how})")
    for key in sorted(set(EXCEPTIONS) - seen):
        problems.append(f"exception {key[0]} -> {key[1]} no longer occurs: remove it")
    if len(EXCEPTIONS) > MAX_EXCEPTIONS:
        problems.append(f"{len(EXCEPTIONS)} exceptions, at most {MAX_EXCEPTIONS}")
    # The public headers and the footprint library sit below every floor.
    for base, lib in (("splat/include", "public header"), ("footprint", "footprint")):
        for path in sources(os.path.join(repo, base)):
            rel = os.path.relpath(path, repo).replace(os.sep, "/")
            with open(path, encoding="utf-8", errors="replace") as f:
                text = f.read()
            for header in INCLUDE.findall(text):
                first = header.split("/")[0]
                if floor_of(first) is not None or (lib == "footprint" and first == "splat"):
                    problems.append(f"{rel}: {lib} includes \"{header}\"")
    return problems


def self_test():
    """The check on small trees with known faults: each must be found."""
    cases = {
        "back include": ({"model/a.h": '#include "frame/b.h"', "frame/b.h": ""}, "floor 1"),
        "sibling": ({"splatters/a.cpp": '#include "reference/b.h"', "reference/b.h": ""},
                    "sibling"),
        "sibling the other way": ({"splatters/a.cpp": '#include "gaussians/b.h"',
                                   "gaussians/b.h": ""}, "sibling"),
        "unknown folder": ({"misc/a.cpp": ""}, "on no floor"),
        "outer layer": ({"analysis/a.cpp": '#include "render_options.h"'}, "not in splat/src"),
        "public header": ({"model/a.h": "", "../include/splat/x.h": '#include "model/a.h"'},
                          "public header includes"),
        "down is fine": ({"dispatch/a.cpp": '#include "frame/b.h"\n#include "model/c.h"\n'
                                            '#include "a.h"\n#include "splat/x.h"',
                          "frame/b.h": "", "model/c.h": "", "dispatch/a.h": ""}, None),
        "allowed sibling use": ({"gaussians/a.cpp": '#include "splatters/b.h"',
                                 "splatters/b.h": ""}, None),
    }
    failed = 0
    for name, (files, expect) in cases.items():
        with tempfile.TemporaryDirectory() as repo:
            for rel, text in files.items():
                path = os.path.normpath(os.path.join(repo, "splat", "src", rel))
                os.makedirs(os.path.dirname(path), exist_ok=True)
                with open(path, "w") as f:
                    f.write(text + "\n")
            problems = check(repo)
        ok = (not problems) if expect is None else any(expect in p for p in problems)
        if not ok:
            failed += 1
            print(f"self-test '{name}': expected {expect or 'no problem'}, got {problems}")
    global EXCEPTIONS
    saved, EXCEPTIONS = EXCEPTIONS, {("model/a.h", "frame/b.h"): "test"}
    with tempfile.TemporaryDirectory() as repo:
        os.makedirs(os.path.join(repo, "splat", "src", "model"))
        open(os.path.join(repo, "splat", "src", "model", "a.h"), "w").close()
        stale = check(repo)
    EXCEPTIONS = saved
    if not any("no longer occurs" in p for p in stale):
        failed += 1
        print(f"self-test 'stale exception': got {stale}")
    print("self-test: " + ("ok" if not failed else f"{failed} failed"))
    return 1 if failed else 0


def main():
    if sys.argv[1:] == ["--self-test"]:
        return self_test()
    repo = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "..")
    problems = check(os.path.abspath(repo))
    for p in problems:
        print("layers: " + p)
    if not problems:
        print("layers: every include in splat/src runs down its floors")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
