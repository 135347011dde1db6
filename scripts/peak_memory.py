#!/usr/bin/env python3
"""Runs a command and reports its peak anonymous and peak total resident memory.

    scripts/peak_memory.py -- haarshift relight render scene.hsr -o frame.png

Linux keeps a high-water mark of the whole resident set (VmHWM, the child's ru_maxrss) but
none of its anonymous part alone, which is what a memory-mapped file does not add to. So
RssAnon is sampled from /proc/PID/status every millisecond while the command runs, and its
largest value kept; ru_maxrss comes from wait4 and is exact. The command's standard output
goes to standard error; this script's own standard output is one JSON line:
{"rss_anon_peak": bytes, "rss_file_peak": bytes, "max_rss": bytes, "samples": n, "rc": code}
"""

import json
import os
import subprocess
import sys
import time


def status_kib(pid, names):
    """The named `Name:  123 kB` fields of /proc/PID/status, in KiB (None once it has gone)."""
    try:
        with open(f"/proc/{pid}/status") as f:
            text = f.read()
    except OSError:
        return None
    found = {}
    for line in text.splitlines():
        key, _, rest = line.partition(":")
        if key in names:
            found[key] = int(rest.split()[0])
    return found


def main():
    args = sys.argv[1:]
    if args[:1] == ["--"]:
        args = args[1:]
    if not args:
        sys.exit("usage: peak_memory.py -- COMMAND [ARGS...]")
    child = subprocess.Popen(args, stdout=sys.stderr)
    anon = file = samples = 0
    while True:
        pid, status, usage = os.wait4(child.pid, os.WNOHANG)
        if pid:
            break
        fields = status_kib(child.pid, {"RssAnon", "RssFile"})
        if fields:
            anon = max(anon, fields.get("RssAnon", 0))
            file = max(file, fields.get("RssFile", 0))
            samples += 1
        time.sleep(0.001)
    print(
        json.dumps(
            {
                "rss_anon_peak": anon * 1024,
                "rss_file_peak": file * 1024,
                "max_rss": usage.ru_maxrss * 1024,
                "samples": samples,
                "rc": os.waitstatus_to_exitcode(status),
            }
        )
    )


if __name__ == "__main__":
    main()
