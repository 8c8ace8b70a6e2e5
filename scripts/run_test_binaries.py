#!/usr/bin/env python3
"""Builds the workspace's test binaries once (cargo) and runs them two at a time.

`cargo test` runs its test binaries one after another; a binary whose last long test runs
alone leaves the second core idle (a third of the test phase's wall time on CI's two cores).
This runs the same binaries, with the same arguments cargo would pass, in the package's
directory as cargo does, as many at once as there are cores, the longest known first, and
prints each binary's whole output when it finishes. Exit status 1 when any binary fails (their
names are listed at the end), 2 when the build fails.

Usage: run_test_binaries.py [CARGO_ARGS...] -- [TEST_BINARY_ARGS...]
"""

import json
import os
import subprocess
import sys
import threading
import time

# Binaries measured longest on CI's two cores: started first so the short ones fill the gaps
# (`check` and `paper_schemes` were unlisted and ran last, the second core idle for a minute).
LONGEST_FIRST = [
    "hardware",
    "gpu",
    "check",
    "adaptive",
    "tessera",
    "catmull_clark",
    "schemes",
    "paper_schemes",
    "bench",
    "cli",
    "view",
    "instanced",
    "esc",
]


def main() -> int:
    argv = sys.argv[1:]
    split = argv.index("--") if "--" in argv else len(argv)
    cargo_args, test_args = argv[:split], argv[split + 1 :]
    build = subprocess.Popen(
        ["cargo", "test", "--no-run", "--message-format=json-render-diagnostics", *cargo_args],
        stdout=subprocess.PIPE,
        text=True,
    )
    binaries = []
    for line in build.stdout:
        try:
            message = json.loads(line)
        except json.JSONDecodeError:
            continue
        if message.get("reason") == "compiler-artifact" and message.get("profile", {}).get("test") and message.get("executable"):
            target = message["target"]
            directory = os.path.dirname(message["manifest_path"])
            binaries.append((target["name"], target["kind"][0], message["executable"], directory))
    if build.wait() != 0:
        return 2

    def rank(binary):
        name = binary[0]
        return LONGEST_FIRST.index(name) if name in LONGEST_FIRST else len(LONGEST_FIRST)

    queue = sorted(binaries, key=rank)
    lock = threading.Lock()
    failed = []

    def worker():
        while True:
            with lock:
                if not queue:
                    return
                name, kind, executable, directory = queue.pop(0)
            start = time.monotonic()
            run = subprocess.run([executable, *test_args], cwd=directory, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
            with lock:
                relative = os.path.relpath(directory)
                print(f"     Running {kind} {name} of {relative} ({time.monotonic() - start:.1f} s)", flush=True)
                print(run.stdout, flush=True)
                if run.returncode != 0:
                    failed.append(f"{relative}: {kind} {name} (exit status {run.returncode})")

    workers = [threading.Thread(target=worker) for _ in range(os.cpu_count() or 2)]
    for w in workers:
        w.start()
    for w in workers:
        w.join()
    if failed:
        print("failed test binaries:\n  " + "\n  ".join(failed), flush=True)
        return 1
    print(f"all {len(binaries)} test binaries passed", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
