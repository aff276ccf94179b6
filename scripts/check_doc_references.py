#!/usr/bin/python3
"""Checks that every cited section of a Markdown page exists (scripts/check-doc-references).

The docs, the code comments and the scripts point at the measurement behind a
number by page and section title, as in (docs/validation.md, "Rule (c): a
lag of one sample") or validation.md "Generator version 2". A section that is
renamed, or moved to docs/history/, leaves such a pointer dangling without
any test failing; this finds them.

A citation is a Markdown file's name followed by a quoted title: the name,
then a space, a comma, a colon or an opening parenthesis, then the title in
double quotes (a name followed at once by a quote is a string literal's and
cites nothing). The title may run over a line break (in a comment, the continuation's
comment leader, # // /// * --, is dropped) and may be written \"...\" inside
a string literal. Files searched: those git lists (tracked, and new ones not
ignored), but fuzz/, CSV files and binary files. The cited file is looked up
relative to the repository's root, then docs/ (a bare validation.md is
docs/validation.md), then the citing file's folder; a file outside the
repository (../shared/METHOD.md, METHOD.md) is skipped. The citation holds
when a heading of that file (any level, the text after the #s, outside fenced
blocks) starts with the title: case-sensitive, so that a title may be cited by
its beginning. A quoted title without a file name (a section of the same page,
"above") is not checked.

Prints each citation that does not resolve as FILE:LINE: cited "TITLE" not
found in PAGE, and exits 1 if there is any, 0 otherwise.
Usage: scripts/check_doc_references.py REPO"""

import re
import subprocess
import sys
from pathlib import Path

# A Markdown file's name: path components of word characters, dots and
# dashes, not preceded by one of them (so that a URL's tail or a longer name
# is not cut in two).
NAME = re.compile(r"(?<![\w./-])((?:\.\./)*(?:[\w.-]+/)*[\w.-]+\.md)(?![\w-])")
# What may stand between the name and the opening quote: a closing backtick
# or "'s", then at least a space, a comma, a colon or a parenthesis.
QUOTED = re.compile(r"^`?(?:'s)?(?:\s*[,:(]\s*|\s+)\"([^\"]+)\"")
COMMENT_LEADER = re.compile(r"^\s*(?:///?|#+|\*|--)\s?")
HEADING = re.compile(r"^#{1,6}\s+(.*?)\s*#*\s*$")
FENCE = re.compile(r"^\s*(```|~~~)")
CONTINUATION_LINES = 3


def listed_files(repo):
    out = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
                         cwd=repo, capture_output=True, check=True).stdout
    for name in sorted(set(out.decode().split("\0"))):
        if not name or name.startswith("fuzz/") or name.lower().endswith(".csv"):
            continue
        path = repo / name
        if path.is_file():
            yield name, path


def read_text(path):
    """The file's text, or None when it is binary (a NUL byte, or not UTF-8)."""
    data = path.read_bytes()
    if b"\0" in data[:8192]:
        return None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        return None


def headings(text):
    """The text of every heading outside fenced blocks."""
    out, fenced = [], False
    for line in text.split("\n"):
        if FENCE.match(line):
            fenced = not fenced
        elif not fenced:
            m = HEADING.match(line)
            if m:
                out.append(m.group(1))
    return out


def citations(name, text):
    """(line number, cited file, title) of each citation in a file's text."""
    lines = text.split("\n")
    markdown = name.endswith(".md")
    for number, line in enumerate(lines, 1):
        if ".md" not in line:
            continue
        for m in NAME.finditer(line):
            after = [line[m.end():]]
            for following in lines[number:number + CONTINUATION_LINES]:
                after.append(following if markdown else COMMENT_LEADER.sub("", following, count=1))
            raw = " ".join(after).replace('\\"', '"')
            joined = (" " if raw[:1].isspace() else "") + " ".join(raw.split())
            q = QUOTED.match(joined)
            if q:
                yield number, m.group(1), q.group(1).strip()


def resolve(repo, citing, cited):
    """The cited page as a path inside the repository, or None when it lies outside."""
    for base in (repo, repo / "docs", (repo / citing).parent):
        candidate = (base / cited).resolve()
        if candidate.is_file():
            return candidate if candidate.is_relative_to(repo) else None
    return False


def main(argv):
    if len(argv) != 1:
        print(__doc__, file=sys.stderr)
        return 2
    repo = Path(argv[0]).resolve()
    pages, problems, checked = {}, [], 0
    for name, path in listed_files(repo):
        text = read_text(path)
        if text is None:
            continue
        for number, cited, title in citations(name, text):
            page = resolve(repo, name, cited)
            if page is None:
                continue
            if page is False:
                if Path(cited).name != "METHOD.md" and not cited.startswith("../"):
                    problems.append(f"{name}:{number}: cited \"{title}\" in {cited}, which is not in the repository")
                continue
            if page not in pages:
                pages[page] = headings(page.read_text())
            checked += 1
            if not any(h.startswith(title) for h in pages[page]):
                problems.append(f"{name}:{number}: cited \"{title}\" not found in {page.relative_to(repo)}")
    for p in problems:
        print(p)
    if problems:
        print(f"{len(problems)} of {checked} cited section(s) not found")
        return 1
    print(f"every cited section resolves ({checked} citations of {len(pages)} pages)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
