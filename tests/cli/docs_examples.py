"""The examples of docs/*.md run as written, and print what the docs show.

Every fenced block holding a `terrapolis ...` command says what it is in its info string:
- ```sh test      an example, run as a bash -euo pipefail script;
- ```console test an example as a transcript: each `$ command` line (with its `\\` continuation
                  lines) is run, and the lines shown under it must appear, in order, in what it
                  printed (stdout then stderr); it must fail exactly when it shows
                  `terrapolis: error:`. Timings (`0.28 s`, `(12 s left)`) are masked on both sides,
                  and a line `...` stands for printed lines left out of the page;
- ```text         a usage synopsis (DEM, OUTDIR, [--option] placeholders): not run;
- ```sh bench     a benchmark (bench/*: minutes, peer tools, ../shared/dems): not run here, but every
                  bench/ script it names must exist, and be executable where it is the command.
A `terrapolis` command in any other block (```, ```sh, ```console) fails the test: a real example
either runs or is marked as a synopsis.
Blocks of one page run in order in one scratch folder holding links to sample_dems/, tests/, src/,
plugins/ and the build folder (build/, from TERRAPOLIS_BUILD_DIR), so a page's later examples read
what its earlier ones wrote. `terrapolis` is the binary under test.
Usage: docs_examples.py TERRAPOLIS SOURCE_DIR
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

TESTED = re.compile(r"^(sh|console) test$")
SHELL_INFO = {"", "sh", "bash", "shell", "console"}  # fences whose `terrapolis` lines must be tested
COMMAND = re.compile(r"(^|[\s;&|(])terrapolis\s+[-\w]")  # `terrapolis hydro ...`, not `terrapolis:`
BENCH_SCRIPT = re.compile(r"(?<![\w./])bench/[\w./-]+")
ASSIGNMENT = re.compile(r"^(\w+=\S*\s+)*")
TIMING = re.compile(r"\d+(\.\d+)? s\b")
ELISION = "..."


def fences(page):
    """(line number, info string, lines) of every fenced block of a page."""
    found, current = [], None
    for number, line in enumerate(page.read_text().splitlines(), 1):
        if current is None:
            if line.startswith("```"):
                current = (number, line[3:].strip(), [])
        elif line.startswith("```"):
            found.append(current)
            current = None
        else:
            current[2].append(line)
    if current is not None:
        sys.exit(f"FAIL: {page.name}:{current[0]}: unclosed block")
    return found


def untested_command(info, lines):
    """The first `terrapolis` command line of a block that is neither tested nor marked, or None."""
    if info not in SHELL_INFO:
        return None
    for line in lines:
        if not line.lstrip().startswith("#") and COMMAND.search(line):
            return line
    return None


def bench_problems(source, lines):
    """What is wrong with the bench/ scripts a ```sh bench block names (missing, not executable)."""
    problems = []
    for line in lines:
        command = line.split(" #")[0].strip()
        for name in BENCH_SCRIPT.findall(command):
            script = source / name
            if not script.is_file():
                problems.append(f"{name} does not exist")
            elif ASSIGNMENT.sub("", command).split()[0] == name and not os.access(script, os.X_OK):
                problems.append(f"{name} is run as a command but is not executable")
    return problems


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
    """The first expected line not printed in order (masked), or None when they all were."""
    printed = [masked(line) for line in printed]
    at = 0
    for line in expected:
        if line.strip() == ELISION:
            continue
        want = masked(line)
        while at < len(printed) and printed[at] != want:
            at += 1
        if at == len(printed):
            return line
        at += 1
    return None


def scratch_folder(work, source, build):
    """A page's folder: links to what its examples read (samples, test data, headers, plugins, build)."""
    work.mkdir(parents=True)
    for name in ("sample_dems", "tests", "src", "plugins"):
        os.symlink(source / name, work / name)
    if build is not None:
        os.symlink(build, work / "build")


def main():
    terrapolis, source = Path(sys.argv[1]).resolve(), Path(sys.argv[2]).resolve()
    build = os.environ.get("TERRAPOLIS_BUILD_DIR")
    if build is None and (terrapolis.parents[2] / "CMakeCache.txt").is_file():
        build = terrapolis.parents[2]  # build/src/cli/terrapolis
    scratch = Path(tempfile.mkdtemp(prefix="tp-docs-"))
    bin_dir = str(scratch / "bin")
    os.mkdir(bin_dir)
    os.symlink(terrapolis, os.path.join(bin_dir, "terrapolis"))
    env = dict(os.environ, PATH=bin_dir + os.pathsep + os.environ["PATH"])
    tested = 0
    failures = []
    for page in sorted((source / "docs").glob("*.md")):
        page_blocks = []
        for number, info, lines in fences(page):
            where = f"docs/{page.name}:{number}"
            if TESTED.match(info):
                page_blocks.append((number, info.split()[0], lines))
            elif info == "sh bench":
                failures += [f"{where}: {problem}" for problem in bench_problems(source, lines)]
            elif (line := untested_command(info, lines)) is not None:
                failures.append(f"{where}: `{line.strip()}` is in a ```{info} block: fence a real example "
                                "```sh test or ```console test, a synopsis ```text, a benchmark ```sh bench")
        if not page_blocks:
            continue
        work = scratch / page.stem
        scratch_folder(work, source, build)
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
