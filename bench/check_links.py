#!/usr/bin/env python3
"""Checks the relative links of README.md and docs/*.md.

    bench/check_links.py [FILE.md ...]      (default: README.md docs/*.md)

FILE paths are relative to the repository root.

Every [text](target) whose target is not a URL must name an existing file or directory,
relative to the page, and a #fragment must be the GitHub anchor of a heading of the page
it points to. Links inside code spans and fenced code blocks are not links. Prints one line
per broken link (file:line: target: what is wrong) and exits 1 if there is any.
"""
import glob
import os
import re
import sys

LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(([^()\s]+)(?:\s+\"[^\"]*\")?\)")
HEADING = re.compile(r"^(#{1,6})\s+(.*?)\s*#*\s*$")


def strip_code(line):
    """The line with its code spans blanked out."""
    return re.sub(r"`[^`]*`", lambda m: " " * len(m.group(0)), line)


def prose_lines(path):
    """(line number, text) of the lines outside fenced code blocks."""
    fence = None
    with open(path, encoding="utf-8") as f:
        for number, line in enumerate(f, 1):
            stripped = line.lstrip()
            if fence is None and (stripped.startswith("```") or stripped.startswith("~~~")):
                fence = stripped[:3]
                continue
            if fence is not None:
                if stripped.startswith(fence):
                    fence = None
                continue
            yield number, line.rstrip("\n")


def anchor(heading):
    """GitHub's anchor of a heading: lower case, punctuation dropped, spaces to '-'."""
    text = re.sub(r"`([^`]*)`", r"\1", heading)
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", text)
    text = text.strip().lower()
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(path, cache={}):
    if path not in cache:
        seen = {}
        found = set()
        for _, line in prose_lines(path):
            m = HEADING.match(line)
            if m:
                a = anchor(m.group(2))
                n = seen.get(a, 0)
                seen[a] = n + 1
                found.add(a if n == 0 else "%s-%d" % (a, n))
        cache[path] = found
    return cache[path]


def check(path):
    errors = []
    base = os.path.dirname(path)
    for number, line in prose_lines(path):
        for m in LINK.finditer(strip_code(line)):
            target = m.group(1)
            if re.match(r"^[a-z][a-z0-9+.-]*:", target) or target.startswith("//"):
                continue  # a URL
            file_part, _, fragment = target.partition("#")
            dest = os.path.normpath(os.path.join(base, file_part)) if file_part else path
            if not os.path.exists(dest):
                errors.append("%s:%d: %s: no such file" % (path, number, target))
                continue
            if fragment:
                if not dest.endswith(".md"):
                    errors.append("%s:%d: %s: a fragment of a file that is not a page"
                                  % (path, number, target))
                elif fragment not in anchors(dest):
                    errors.append("%s:%d: %s: no heading with that anchor in %s"
                                  % (path, number, target, dest))
    return errors


def main(argv):
    root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    os.chdir(root)
    files = argv[1:] or ["README.md"] + sorted(glob.glob("docs/*.md"))
    errors = [e for f in files for e in check(f)]
    for e in errors:
        print(e)
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
