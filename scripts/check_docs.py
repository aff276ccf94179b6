#!/usr/bin/python3
"""Runs the examples of README.md and docs/guide/*.md (scripts/check-docs).

A page's examples run in order in a scratch folder of their own laid out
as a checkout is: `build`, `samples`, `python`, `tools` and `scripts` link to
the repository's, `../shared` to the shared folder beside it, so that a
command reads as a researcher types it from the repository's root and every
output file goes to the scratch folder. Each fenced block is one example:

- ```console: lines starting with "$ " are commands (a line ending in "\\"
  continues), the lines after them their expected standard output. The
  block's commands run in one bash (set -e), and its output must equal the
  expected, where a line "..." stands for any lines and "..." inside a line
  for any text (timings, versions). Standard error is shown on failure only.
- ```sh: commands run for their exit status only (0).
- ```python: run by /usr/bin/python3 with the module on its path; exit 0.
- ```pycon: ">>> " and "... " lines are Python, the rest its printed output,
  compared by doctest's rules ("..." for any text).
- a block whose opening line carries "no-check" (```sh no-check) is shown,
  not run (a command that needs what CI has not: MPI ranks, hours).

The environment: D=../shared/data/felder-stepped-spillway (the ten real
recordings), PYTHONPATH=build/python. Exit status 0 when every example
passes, 1 otherwise (each failure printed with its page and line).
Usage: scripts/check_docs.py REPO [PAGE...] [--update]  (--update writes each
console block's actual output into the page, for authoring; review the diff)."""

import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

FENCE = re.compile(r"^```(\w+)?(.*)$")


def blocks(text):
    """(language, options, first line number, lines) of each fenced block."""
    out, lines, inside = [], text.split("\n"), None
    for number, line in enumerate(lines, 1):
        m = FENCE.match(line)
        if inside is None and m:
            inside = (m.group(1) or "", m.group(2).strip(), number + 1, [])
        elif inside is not None and line.startswith("```"):
            out.append(inside)
            inside = None
        elif inside is not None:
            inside[3].append(line)
    return out


def console_parts(lines, prompt="$ ", more=None):
    """The script and the expected output of a console (or pycon) block."""
    script, expected, continuing = [], [], False
    for line in lines:
        if continuing:
            script.append(line)
            continuing = line.endswith("\\")
        elif line.startswith(prompt) or (more and line.startswith(more) and script):
            script.append(line[len(prompt):])
            continuing = line.endswith("\\")
        else:
            expected.append(line)
    while expected and not expected[-1].strip():
        expected.pop()
    return script, expected


def matches(expected, actual):
    """Line-wise comparison with "..." lines (any lines) and "..." in a line (any text)."""
    def line_ok(e, a):
        if "..." not in e:
            return e.rstrip() == a.rstrip()
        pattern = ".*".join(re.escape(p) for p in e.rstrip().split("..."))
        return re.fullmatch(pattern, a.rstrip()) is not None

    def walk(i, j):
        while i < len(expected):
            if expected[i].strip() == "...":
                return any(walk(i + 1, k) for k in range(j, len(actual) + 1))
            if j >= len(actual) or not line_ok(expected[i], actual[j]):
                return False
            i, j = i + 1, j + 1
        return j == len(actual)

    return walk(0, 0)


def run(command, cwd, env, timeout=900):
    return subprocess.run(command, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)


def scratch_for(repo):
    root = Path(tempfile.mkdtemp(prefix="pdp-docs-"))
    (root / "shared").symlink_to(repo.parent / "shared")
    work = root / "repo"
    work.mkdir()
    for name in ("build", "samples", "python", "tools", "scripts", "docs"):
        (work / name).symlink_to(repo / name)
    return root, work


def check_page(repo, page, update):
    text = page.read_text()
    failures, new_text_lines = [], text.split("\n")
    root, work = scratch_for(repo)
    env = dict(os.environ, D="../shared/data/felder-stepped-spillway", PYTHONPATH=str(repo / "build" / "python"),
               PDP_LOG_LEVEL="error", COLUMNS="200")
    replacements = []
    try:
        for language, options, first, lines in blocks(text):
            if "no-check" in options or language not in ("console", "sh", "python", "pycon"):
                continue
            where = f"{page.relative_to(repo)}:{first}"
            start = time.monotonic()
            if language == "console":
                script, expected = console_parts(lines)
                result = run(["bash", "-e", "-o", "pipefail", "-c", "\n".join(script)], work, env)
                actual = result.stdout.rstrip("\n").split("\n") if result.stdout.strip() else []
                if result.returncode != 0:
                    failures.append(f"{where}: exit {result.returncode}\n{result.stderr[-3000:]}")
                elif update:
                    replacements.append((first, lines, expected, actual))
                elif not matches(expected, actual):
                    failures.append(f"{where}: output changed\n--- shown\n" + "\n".join(expected) +
                                    "\n--- now\n" + "\n".join(actual))
            elif language == "pycon":
                # doctest's rules: each ">>> " example's output, "..." for any text.
                example = work / "example.txt"
                example.write_text("\n".join(lines) + "\n")
                result = run(["/usr/bin/python3", "-c",
                              "import doctest, sys\n"
                              "r = doctest.testfile('example.txt', module_relative=False, "
                              "optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)\n"
                              "sys.exit(1 if r.failed else 0)"], work, env)
                if result.returncode != 0:
                    failures.append(f"{where}: {result.stdout[-3000:]}{result.stderr[-2000:]}")
            else:
                command = ["bash", "-e", "-o", "pipefail", "-c", "\n".join(lines)] if language == "sh" else \
                          ["/usr/bin/python3", "-c", "\n".join(lines)]
                result = run(command, work, env)
                if result.returncode != 0:
                    failures.append(f"{where}: exit {result.returncode}\n{result.stderr[-3000:]}")
            print(f"  {where} ({language}, {time.monotonic() - start:.1f} s)", flush=True)
    finally:
        shutil.rmtree(root, ignore_errors=True)
    if update and replacements:
        # The block's commands in their order, then its output as it is now.
        for first, lines, expected, actual in reversed(replacements):
            commands, continuing = [], False
            for line in lines:
                if continuing or line.startswith(("$ ", ">>> ")) or (commands and line.startswith("... ")):
                    commands.append(line)
                    continuing = line.endswith("\\")
            new_text_lines[first - 1:first - 1 + len(lines)] = commands + actual
        page.write_text("\n".join(new_text_lines))
    return failures


def main(argv):
    update = "--update" in argv
    args = [a for a in argv if a != "--update"]
    if not args:
        print(__doc__, file=sys.stderr)
        return 2
    repo = Path(args[0]).resolve()
    pages = [Path(p).resolve() for p in args[1:]] or [repo / "README.md", *sorted((repo / "docs" / "guide").glob("*.md"))]
    if not (repo / "build" / "tools" / "pdp").exists():
        print(f"{repo / 'build/tools/pdp'}: not built; run scripts/build first", file=sys.stderr)
        return 2
    if not (repo.parent / "shared" / "data").exists():
        print(f"skipped: {repo.parent / 'shared/data'} is absent, and the examples read the real recordings there")
        return 0
    failures = []
    for page in pages:
        print(page.relative_to(repo), flush=True)
        failures += check_page(repo, page, update)
    for f in failures:
        print(f"FAIL {f}\n", file=sys.stderr)
    print(f"{len(failures)} failing example(s)" if failures else "every example passes")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
