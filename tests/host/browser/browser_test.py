#!/usr/bin/env python3
"""The live view in a real browser (issue 11), one CTest test per mode.

tissue-host runs the frog with the mouse as its device (--mouse) on a free loopback port; headless
Chromium (Debian's, driven by playwright-core through view_test.mjs) opens the page. Modes:
  cut   one viewer receives frames and a scripted mouse drag cuts the frog: the host must report
        cut tets > 0, frames sent, no NaN; a screenshot is saved.
  bad   a page sends truncated, huge, binary, wrong-type, replayed and flooding messages: the host
        keeps running to its end and counts them (malformed, oversized, out of order, flood).
  rate  N viewers watch (no cut) for a while: frames per second per page and the haptic period,
        for docs/BENCHMARKS.md (not a pass/fail on speed: the machines are shared).
Exit 0 on success; the reason otherwise. Writes result.json, the host's session folder and the
screenshot into --out.
"""
import argparse
import json
import pathlib
import re
import signal
import subprocess
import sys
import threading


def fail(message):
    print("browser test: FAILED: " + message)
    sys.exit(1)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--host", required=True, help="the tissue-host executable")
    parser.add_argument("--scenario", required=True)
    parser.add_argument("--script", required=True, help="view_test.mjs")
    parser.add_argument("--out", required=True)
    parser.add_argument("--mode", choices=["cut", "bad", "rate"], default="cut")
    parser.add_argument("--viewers", type=int, default=1)
    parser.add_argument("--seconds", type=float, default=4.0, help="how long the pages watch")
    parser.add_argument("--rt", action="store_true", help="let the host ask for SCHED_FIFO (benchmarks)")
    args = parser.parse_args()

    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    # Page start-up, the drag and the watch, with ample room (Chromium starts slowly on a busy
    # machine): the session is ended with Ctrl-C once the browser script is done.
    duration = args.seconds + 60.0
    host = subprocess.Popen(
        [args.host, "run", args.scenario, "--mouse", "--port", "0", "--output", str(out / "session"),
         "--duration", str(duration)] + ([] if args.rt else ["--no-rt-priority"]),
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    lines = []
    url = None
    found = threading.Event()

    def read_host():
        nonlocal url
        for line in host.stdout:
            lines.append(line)
            match = re.search(r"live view: (http://\S+)", line)
            if match and url is None:
                url = match.group(1)
                found.set()
        found.set()

    reader = threading.Thread(target=read_host, daemon=True)
    reader.start()
    if not found.wait(120) or url is None:
        host.kill()
        fail("tissue-host did not start its view:\n" + "".join(lines))

    command = ["node", args.script, "--url", url, "--viewers", str(args.viewers), "--seconds", str(args.seconds),
               "--json", str(out / "browser.json"), "--screenshot", str(out / "view.png")]
    if args.mode == "cut":
        command.append("--drag")
    if args.mode == "bad":
        command.append("--bad-messages")
    try:
        browser = subprocess.run(command, capture_output=True, text=True, timeout=args.seconds + 90)
    except subprocess.TimeoutExpired:
        host.kill()
        fail("the browser script did not finish")
    print(browser.stdout, end="")
    if browser.returncode != 0:
        host.kill()
        fail("the browser script failed:\n" + browser.stdout + browser.stderr)
    host.send_signal(signal.SIGINT)
    try:
        host.wait(timeout=duration + 120)
    except subprocess.TimeoutExpired:
        host.kill()
        fail("tissue-host did not end")
    reader.join(5)
    print("".join(lines), end="")
    if host.returncode != 0:
        fail("tissue-host ended with code %d" % host.returncode)

    summary = json.loads((out / "session" / "summary.json").read_text())
    page = json.loads((out / "browser.json").read_text())
    view = summary.get("view")
    if view is None:
        fail("summary.json has no view counters")
    result = {"mode": args.mode, "viewers": args.viewers, "summary_view": view, "browser": page,
              "haptic_period_us": summary["haptic_period_us"], "deadline_misses": summary["deadline_misses"],
              "tissue_step_ms": summary["tissue_step_ms"], "realtime_factor": summary["realtime_factor"],
              "cut_tets": summary["cut_tets"]}
    (out / "result.json").write_text(json.dumps(result, indent=2))
    if summary["nan_detected"]:
        fail("NaN in the session")
    if view["frames_sent"] == 0 or min(page.get("frames_per_s", [0])) <= 0:
        fail("no frames reached the page(s)")
    if args.mode == "cut" and summary["cut_tets"] == 0:
        fail("the mouse drag cut nothing (cut_tets = 0)")
    if args.mode == "bad":
        for key in ("malformed", "oversized", "flood", "out_of_order"):
            if view[key] == 0:
                fail("the host counted no %s message: %s" % (key, view))
    print("browser test (%s, %d viewer(s)): ok; frames/s per page %s, haptic period p50/p99/max %s us, cut tets %d"
          % (args.mode, args.viewers, page.get("frames_per_s"), summary["haptic_period_us"], summary["cut_tets"]))


if __name__ == "__main__":
    main()
