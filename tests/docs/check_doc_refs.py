#!/usr/bin/python3
"""Checks splat's documentation references and links (ctest docs.references).

Usage: check_doc_refs.py [--list] [--allow FILE] SOURCE_ROOT

1. Every documentation reference in code, tests, scripts, CMake files and documents names a
   document and section that exist. The syntax is `docs/NAME.md` (a topic document of
   splat/docs/) or `README.md`, optionally followed by a quoted heading of that document:
       docs/parallel.md        docs/accuracy.md "Aliasing and EWA"        README.md "Gallery"
   (in a C string the quotes are escaped; in a comment the heading may wrap onto the next
   comment line). References in the older spellings (the word README without `.md`, the
   design contract's old file name) are reported as old-style.
2. Every relative link of README.md and splat/docs/*.md resolves: the file exists and, for a
   `#anchor`, the target Markdown file has a heading with that GitHub anchor.
3. No work-item references (an issue number, "this issue") anywhere: code and documents say
   what the code does and why.

Files listed in the allow file (default: allowed_paths.txt beside this script; one path
relative to SOURCE_ROOT per line, a folder when it ends in '/', `#` comments) may still hold
old-style and work-item references: they are counted, listed with --list, and do not fail the check. Exit status 0
when nothing else is found, 1 otherwise, 2 on a usage error.
"""
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
TEXT_SUFFIXES = (".h", ".hpp", ".cpp", ".cc", ".c", ".py", ".pyi", ".sh", ".cmake", ".in",
                 ".txt", ".md", ".supp", ".json")
SKIP_DIRS = {".git", "out", "node_modules", "__pycache__"}
# This checker and its allow file spell the patterns they look for.
SELF = {"tests/docs/check_doc_refs.py", "tests/docs/allowed_paths.txt"}

WRAP = r"(?:[ \t]*\n[ \t]*(?://+|#+|\*+)[ \t]*)"
HEADING_NAME = r"[^\"\\\n]{1,80}(?:" + WRAP + r"[^\"\\\n]{1,80})?"
REF = re.compile(r"(?<![\w/.-])(?P<path>(?:splat/)?docs/[\w.-]+\.md|README\.md)"
                 r"(?:[ \t]+(?P<q>\\?\")(?P<section>" + HEADING_NAME + r")(?P=q))?")
OLD_STYLE = re.compile(r"\bDESIGN\b|\bREADME\b(?!\.md\b|\.txt\b)")
WORK_ITEM = re.compile(r"\b[Ii]ssues?[ \t]+#?\d+|\b(?:[Tt]his|[Tt]hat|[Tt]he) issue's\b|"
                       r"\b[Tt]his issue\b")
LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\((?P<target><[^>]*>|[^)\s]+)(?:\s+\"[^\"]*\")?\)")


def tracked_files(root):
    try:
        out = subprocess.run(["git", "-C", root, "ls-files", "-z", "--cached", "--others",
                              "--exclude-standard"], capture_output=True, check=True)
        names = [n for n in out.stdout.decode().split("\0") if n]
        if names:
            return sorted(n for n in names if os.path.isfile(os.path.join(root, n)))
    except (OSError, subprocess.CalledProcessError):
        pass
    names = []
    for dirpath, dirnames, filenames in os.walk(root):
        dirnames[:] = [d for d in dirnames if d not in SKIP_DIRS and not d.startswith("build")]
        names += [os.path.relpath(os.path.join(dirpath, f), root) for f in filenames]
    return sorted(names)


def is_text(root, rel):
    name = os.path.basename(rel)
    if rel.startswith("build") or "/build/" in rel:
        return False
    if name.endswith(TEXT_SUFFIXES) or name == "CMakeLists.txt":
        return True
    path = os.path.join(root, rel)
    if os.access(path, os.X_OK):  # scripts without a suffix (.ci/run)
        with open(path, "rb") as f:
            return f.read(2) == b"#!"
    return False


def strip_code(md):
    """Markdown without fenced code blocks and inline code (for links and headings)."""
    out, fence = [], False
    for line in md.split("\n"):
        if line.lstrip().startswith("```"):
            fence = not fence
            out.append("")
            continue
        out.append("" if fence else re.sub(r"`[^`]*`", "``", line))
    return out


def headings(md):
    """(text, GitHub anchor) of every ATX heading outside code blocks."""
    result, seen, fence = [], {}, False
    for line in md.split("\n"):
        if line.lstrip().startswith("```"):
            fence = not fence
            continue
        m = None if fence else re.match(r"^#{1,6}[ \t]+(.*?)[ \t#]*$", line)
        if not m:
            continue
        text = m.group(1)
        plain = re.sub(r"[`*]", "", re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", text))
        slug = re.sub(r"[^\w\- ]", "", plain.lower(), flags=re.UNICODE).replace(" ", "-")
        n = seen.get(slug, 0)
        seen[slug] = n + 1
        result.append((text, slug if n == 0 else f"{slug}-{n}"))
    return result


class Checker:
    def __init__(self, root, allowed):
        self.root = root
        self.allowed = allowed
        self.problems = []  # (path, line, message)
        self.tolerated = []
        self.cache = {}

    def allowed_entry(self, rel):
        """The allow-file entry covering `rel`: the path itself, or a folder ending in '/'."""
        for entry in self.allowed:
            if rel == entry or (entry.endswith("/") and rel.startswith(entry)):
                return entry
        return None

    def report(self, rel, line, message, allowable=False):
        entry = (rel, line, message)
        if allowable and self.allowed_entry(rel):
            self.tolerated.append(entry)
        else:
            self.problems.append(entry)

    def doc(self, rel):
        if rel not in self.cache:
            path = os.path.join(self.root, rel)
            if not os.path.isfile(path):
                self.cache[rel] = None
            else:
                with open(path, encoding="utf-8") as f:
                    self.cache[rel] = headings(f.read())
        return self.cache[rel]

    def check_references(self, rel, text):
        for m in REF.finditer(text):
            line = text.count("\n", 0, m.start()) + 1
            path = m.group("path")
            target = path if path == "README.md" else "splat/docs/" + path.split("docs/", 1)[1]
            heads = self.doc(target)
            if heads is None:
                self.report(rel, line, f"reference to {path}: {target} does not exist")
                continue
            if m.group("section"):
                name = re.sub(WRAP, " ", m.group("section")).strip()
                names = {h for h, _ in heads} | {re.sub(r"`", "", h) for h, _ in heads}
                if name not in names:
                    self.report(rel, line, f"reference to {path} \"{name}\": {target} has no "
                                           f"such heading")

    def check_patterns(self, rel, text):
        for pattern, what in ((OLD_STYLE, "old-style documentation reference"),
                              (WORK_ITEM, "work-item reference")):
            for m in pattern.finditer(text):
                line = text.count("\n", 0, m.start()) + 1
                context = text.split("\n")[line - 1].strip()
                self.report(rel, line, f"{what} '{m.group(0)}': {context[:90]}", allowable=True)

    def check_links(self, rel, text):
        base = os.path.dirname(rel)
        for number, line in enumerate(strip_code(text), 1):
            for m in LINK.finditer(line):
                target = m.group("target").strip("<>")
                if re.match(r"^[a-z][a-z0-9+.-]*:", target, re.I):
                    continue  # http:, https:, mailto:
                path, _, anchor = target.partition("#")
                dest = os.path.normpath(os.path.join(base, path)) if path else rel
                if not os.path.exists(os.path.join(self.root, dest)):
                    self.report(rel, number, f"link to {target}: {dest} does not exist")
                    continue
                if anchor:
                    if not dest.endswith(".md"):
                        self.report(rel, number, f"link to {target}: an anchor into a non-"
                                                 f"Markdown file")
                        continue
                    anchors = {a for _, a in self.doc(dest) or []}
                    if anchor not in anchors:
                        self.report(rel, number, f"link to {target}: {dest} has no heading "
                                                 f"with the anchor #{anchor}")

    def run(self):
        for rel in tracked_files(self.root):
            if rel in SELF or not is_text(self.root, rel):
                continue
            try:
                with open(os.path.join(self.root, rel), encoding="utf-8") as f:
                    text = f.read()
            except (UnicodeDecodeError, OSError):
                continue
            self.check_references(rel, text)
            self.check_patterns(rel, text)
            if rel == "README.md" or (rel.startswith("splat/docs/") and rel.endswith(".md")):
                self.check_links(rel, text)


def read_allowed(path):
    allowed = set()
    if path and os.path.isfile(path):
        with open(path) as f:
            for line in f:
                line = line.split("#", 1)[0].strip()
                if line:
                    allowed.add(line)
    return allowed


def main(argv):
    args, listing, allow = [], False, os.path.join(HERE, "allowed_paths.txt")
    it = iter(argv)
    for a in it:
        if a == "--list":
            listing = True
        elif a == "--allow":
            allow = next(it, None)
        else:
            args.append(a)
    if len(args) != 1 or not os.path.isdir(args[0]) or allow is None:
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        return 2
    checker = Checker(os.path.abspath(args[0]), read_allowed(allow))
    checker.run()
    for rel, line, message in checker.problems:
        print(f"{rel}:{line}: {message}")
    if listing:
        for rel, line, message in checker.tolerated:
            print(f"{rel}:{line}: (allowed) {message}")
    stale = sorted(checker.allowed - {checker.allowed_entry(rel) for rel, _, _ in checker.tolerated})
    for rel in stale:
        print(f"check_doc_refs: note: {rel} is allowed but holds nothing to allow; "
              f"remove it from {os.path.basename(allow)}", file=sys.stderr)
    files = len({rel for rel, _, _ in checker.tolerated})
    print(f"check_doc_refs: {len(checker.problems)} problems; {len(checker.tolerated)} old-style "
          f"or work-item references allowed in {files} listed files", file=sys.stderr)
    return 1 if checker.problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
