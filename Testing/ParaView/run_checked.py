"""Runs a ParaView test command and passes only when it exits 0, printed "all checks passed" and
printed no "FAIL" line: pvbatch under MPI can crash in its teardown after a script ends, and a
script that stops early must not pass either. Output is passed through.

usage: run_checked.py [--timeout S] -- COMMAND...
"""
import subprocess
import sys

args = sys.argv[1:]
timeout = 600.0
if args[:1] == ["--timeout"]:
    timeout, args = float(args[1]), args[2:]
if args[:1] == ["--"]:
    args = args[1:]
try:
    run = subprocess.run(args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                         errors="replace", timeout=timeout, stdin=subprocess.DEVNULL)
except subprocess.TimeoutExpired as e:
    sys.stdout.write(e.stdout or "")
    sys.exit(f"run_checked: no answer after {timeout:.0f} s: {' '.join(args)}")
sys.stdout.write(run.stdout)
lines = run.stdout.splitlines()
failed = [l for l in lines if "FAIL" in l]
if run.returncode != 0 or failed or not any("all checks passed" in l for l in lines):
    sys.exit(f"run_checked: exit code {run.returncode}, {len(failed)} FAIL line(s)")
