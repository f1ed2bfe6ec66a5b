"""The examples of docs/*.md run as written, and print what the docs show.

Two kinds of fenced blocks are tested (the info string after the language marks them):
- ```sh test      the block is a shell script, run with bash -euo pipefail;
- ```console test a transcript: each `$ command` line (with its `\\` continuation lines) is run,
                  and the lines shown under it must appear, in order, in what it printed (stdout
                  then stderr); it must fail exactly when it shows `terrapolis: error:`. Timings (`0.28 s`, `(12 s left)`) are masked on both sides.
Blocks of one page run in order in one scratch folder holding links to sample_dems/ and tests/data/,
so a page's later examples read what its earlier ones wrote. `terrapolis` is the binary under test.
Usage: docs_examples.py TERRAPOLIS SOURCE_DIR
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

FENCE = re.compile(r"^```(sh|console) test\s*$")
TIMING = re.compile(r"\d+(\.\d+)? s\b")


def blocks(page):
    """(line number, kind, lines) of every tested block of a page."""
    found, current = [], None
    for number, line in enumerate(page.read_text().splitlines(), 1):
        if current is None:
            match = FENCE.match(line)
            if match:
                current = (number, match.group(1), [])
        elif line.startswith("```"):
            found.append(current)
            current = None
        else:
            current[2].append(line)
    if current is not None:
        sys.exit(f"FAIL: {page.name}:{current[0]}: unclosed block")
    return found


def transcript(lines):
    """[(command, expected lines)] of a console block."""
    steps = []
    for line in lines:
        if line.startswith("$ "):
            steps.append([line[2:], []])
        elif steps and steps[-1][0].endswith("\\") and not steps[-1][1]:
            steps[-1][0] = steps[-1][0][:-1] + " " + line.strip()
        elif steps:
            steps[-1][1].append(line)
        else:
            sys.exit(f"FAIL: output line before any command: {line}")
    return steps


def masked(line):
    return TIMING.sub("<time>", line.rstrip())


def shows(expected, printed):
    """True when the expected lines appear in order in the printed ones (masked)."""
    printed = [masked(line) for line in printed]
    at = 0
    for line in expected:
        want = masked(line)
        while at < len(printed) and printed[at] != want:
            at += 1
        if at == len(printed):
            return line
        at += 1
    return None


def main():
    terrapolis, source = Path(sys.argv[1]).resolve(), Path(sys.argv[2]).resolve()
    scratch = Path(tempfile.mkdtemp(prefix="tp-docs-"))
    bin_dir = str(scratch / "bin")
    os.mkdir(bin_dir)
    os.symlink(terrapolis, os.path.join(bin_dir, "terrapolis"))
    env = dict(os.environ, PATH=bin_dir + os.pathsep + os.environ["PATH"])
    tested = 0
    failures = []
    for page in sorted((source / "docs").glob("*.md")):
        page_blocks = blocks(page)
        if not page_blocks:
            continue
        work = scratch / page.stem
        (work / "tests").mkdir(parents=True)
        os.symlink(source / "sample_dems", work / "sample_dems")
        os.symlink(source / "tests" / "data", work / "tests" / "data")
        for number, kind, lines in page_blocks:
            where = f"docs/{page.name}:{number}"
            if kind == "sh":
                steps = [("\n".join(lines), [])]
            else:
                steps = transcript(lines)
            for command, expected in steps:
                tested += 1
                run = subprocess.run(["bash", "-euo", "pipefail", "-c", command], cwd=work, env=env,
                                     capture_output=True, text=True)
                shows_error = any(line.startswith("terrapolis: error:") for line in expected)
                if (run.returncode != 0) != shows_error:
                    failures.append(f"{where}: `{command.splitlines()[0]}` exited {run.returncode}: "
                                    f"{run.stderr.strip()[-400:]}")
                    continue
                missing = shows(expected, (run.stdout + run.stderr).splitlines())
                if missing is not None:
                    failures.append(f"{where}: `{command}` did not print the documented line\n  {missing}\n"
                                    f"printed:\n{run.stdout}{run.stderr}")
        print(f"{page.name}: {len(page_blocks)} tested blocks")
    shutil.rmtree(scratch)
    if tested == 0:
        sys.exit("FAIL: no tested example in docs/ (```sh test or ```console test blocks)")
    for failure in failures:
        print("FAIL:", failure, file=sys.stderr)
    print(f"{tested} documented commands run, {len(failures)} failed")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
