"""Runs a ParaView test command and passes only when it exits 0, printed "all checks passed" and
printed no "FAIL" line: pvbatch under MPI can crash in its teardown after a script ends, and a
script that stops early must not pass either. Output is passed through.

With --xvfb the command gets an X server of its own: Xvfb started with -displayfd, so that the
server itself picks a free display (xvfb-run -a can pick one a previous server still holds), and
with -noreset, so that a client that connects and leaves (pvbatch probes the display at start)
does not make the server reset under the next connection (seen on a loaded machine).

usage: run_checked.py [--timeout S] [--xvfb] -- COMMAND...
"""
import os
import subprocess
import sys

args = sys.argv[1:]
timeout = 600.0
xvfb = None
while args and args[0] != "--":
    if args[0] == "--timeout":
        timeout, args = float(args[1]), args[2:]
    elif args[0] == "--xvfb":
        args = args[1:]
        read, write = os.pipe()
        xvfb = subprocess.Popen(["Xvfb", "-displayfd", str(write), "-screen", "0", "1280x1024x24",
                                 "-nolisten", "tcp", "-noreset"], pass_fds=(write,),
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        os.close(write)
        with os.fdopen(read) as pipe:
            display = pipe.readline().strip()
        if not display:
            sys.exit("run_checked: Xvfb did not start")
        os.environ["DISPLAY"] = ":" + display
    else:
        sys.exit(f"run_checked: unknown option {args[0]}")
args = args[1:]
try:
    run = subprocess.run(args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                         errors="replace", timeout=timeout, stdin=subprocess.DEVNULL)
except subprocess.TimeoutExpired as e:
    sys.stdout.write(e.stdout or "")
    sys.exit(f"run_checked: no answer after {timeout:.0f} s: {' '.join(args)}")
finally:
    if xvfb:
        xvfb.terminate()
        xvfb.wait()
sys.stdout.write(run.stdout)
lines = run.stdout.splitlines()
failed = [l for l in lines if "FAIL" in l]
if run.returncode != 0 or failed or not any("all checks passed" in l for l in lines):
    sys.exit(f"run_checked: exit code {run.returncode}, {len(failed)} FAIL line(s)")
