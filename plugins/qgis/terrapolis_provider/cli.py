"""Finding and running the terrapolis program: its description, and a run with JSON progress."""
# SPDX-License-Identifier: MIT
import json
import os
import queue
import shutil
import subprocess
import threading


def executable():
    """The terrapolis program: $TERRAPOLIS_BIN, else `terrapolis` on PATH."""
    path = os.environ.get("TERRAPOLIS_BIN") or shutil.which("terrapolis")
    if not path or not os.path.exists(path):
        raise RuntimeError("terrapolis not found: put it on PATH or set TERRAPOLIS_BIN")
    return path


def describe():
    """The command line's own description (`terrapolis --describe-json`)."""
    out = subprocess.run([executable(), "--describe-json"], check=True, capture_output=True, text=True)
    return json.loads(out.stdout)


def run(args, on_progress, on_message, is_cancelled, poll_seconds=0.1):
    """Runs terrapolis with `args` (after --progress json); returns its exit code, or None when
    cancelled (the process is killed). Progress lines {"step", "progress"} go to on_progress(step,
    fraction), other stderr and stdout lines to on_message(line)."""
    with subprocess.Popen([executable(), "--progress", "json"] + list(args), stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, text=True, bufsize=1) as process:
        lines = queue.Queue()

        def pump(stream):
            for line in stream:
                lines.put(line.rstrip("\n"))
            lines.put(None)

        threads = [threading.Thread(target=pump, args=(s,), daemon=True) for s in (process.stdout, process.stderr)]
        for t in threads:
            t.start()
        open_streams = len(threads)
        while open_streams:
            if is_cancelled():
                process.kill()
                process.wait()
                for t in threads:
                    t.join()
                return None
            try:
                line = lines.get(timeout=poll_seconds)
            except queue.Empty:
                continue
            if line is None:
                open_streams -= 1
                continue
            if line.startswith("{"):
                try:
                    item = json.loads(line)
                    on_progress(item["step"], float(item["progress"]))
                    continue
                except (ValueError, KeyError):
                    pass
            if line:
                on_message(line)
        return process.wait()
