#!/usr/bin/env python3
"""Checks that every relative link in README.md, CONTRIBUTING.md and docs/**/*.md resolves.

Usage: python3 docs/check_links.py   (from the repository's top; exit 1 and one line per broken link)

A link is [text](target) or [text](target#anchor), possibly broken across lines. The target must
be an existing file or folder relative to the page; an anchor must match one of the target page's
headings as GitHub spells it (lower case, punctuation dropped, spaces to hyphens).
"""
import pathlib
import re
import sys

LINK = re.compile(r"\]\(\s*([^)\s]+)\s*\)")
HEADING = re.compile(r"^#+\s+(.*?)\s*$", re.MULTILINE)


def Slug(heading):
    text = heading.strip().lower()
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def Anchors(page):
    text = page.read_text(encoding="utf-8")
    return {Slug(h) for h in HEADING.findall(text)}


def BrokenLinks(page):
    broken = []
    text = page.read_text(encoding="utf-8")
    for target in LINK.findall(text):
        if re.match(r"^[a-z]+:", target):  # http:, https:, mailto:
            continue
        path, _, anchor = target.partition("#")
        resolved = (page.parent / path).resolve() if path else page.resolve()
        if not resolved.exists():
            broken.append(f"{page}: {target}: no such file")
        elif anchor and resolved.suffix == ".md" and anchor not in Anchors(resolved):
            broken.append(f"{page}: {target}: no such heading")
    return broken


def main():
    top = pathlib.Path(".")
    pages = [p for p in [top / "README.md", top / "CONTRIBUTING.md"] if p.exists()]
    pages += sorted((top / "docs").rglob("*.md"))
    broken = [line for page in pages for line in BrokenLinks(page)]
    for line in broken:
        print(line)
    print(f"{len(pages)} pages, {len(broken)} broken link(s)", file=sys.stderr)
    return 1 if broken else 0


if __name__ == "__main__":
    sys.exit(main())
