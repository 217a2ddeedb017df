#!/usr/bin/python3
"""Tests of scripts/ibr-dask with real ibr runs on a local Dask cluster.

Usage: ibr_dask_test.py --ibr BUILD/bin/ibr --script scripts/ibr-dask --work DIR

- a batch of 8 captures on 2 workers, one of whose worker processes is killed
  (SIGKILL) while its ibr is half-way through writing: every output appears
  exactly once and complete, nothing staged is left, the summary shows the
  lost attempt on the killed worker and the re-run, and the exit status is 0;
- the same manifest again with --resume skips every job (outputs untouched),
  and a job whose ibr fails is retried, reported with its stderr, exit 1;
- bad manifests: one error naming the file and line, exit 2, nothing run.
"""

import argparse
import json
import os
import shutil
import signal
import subprocess
import sys
import time
import unittest

ARGS = None  # parsed command line (set in __main__)

SLOW = "slow"  # the job whose worker is killed
# (id, shape, rig, size, views): small captures, and one large enough to be
# killed half-way (its staging folder exists for seconds).
# The slow job comes third, so that the worker running it has finished a job
# before: that job must not run again when the worker dies.
JOBS = [
    ("box", "box", "cube", 32, 6),
    ("cup", "cup", "ring:2", 32, 2),
    (SLOW, "sphere", "cube", 256, 6),
    ("mug", "mug", "ring:3", 32, 3),
    ("box-ring", "box", "ring:4", 32, 4),
    ("cup-cube", "cup", "cube", 32, 6),
    ("box-48", "box", "ring:2", 48, 2),
    ("mug-48", "mug", "ring:2", 48, 2),
]
BATCH_TIMEOUT = 240  # seconds; the batch takes far less, this only bounds a hang


def write_wrapper(folder, ibr):
    """An --ibr wrapper that records (worker pid, ibr pid, args) of every start,
    then becomes the real ibr (exec keeps the pid)."""
    path = os.path.join(folder, "ibr-wrapper")
    log = os.path.join(folder, "started.txt")
    with open(path, "w") as f:
        f.write(f'#!/bin/sh\necho "$PPID $$ $*" >> "{log}"\nexec "{ibr}" "$@"\n')
    os.chmod(path, 0o755)
    return path, log


def read_starts(log):
    """[(worker_pid, ibr_pid, args string)] in start order."""
    if not os.path.exists(log):
        return []
    with open(log) as f:
        return [(int(p[0]), int(p[1]), p[2]) for p in (line.rstrip("\n").split(" ", 2) for line in f) if len(p) == 3]


def write_manifest(path, lines):
    with open(path, "w") as f:
        for line in lines:
            f.write((line if isinstance(line, str) else json.dumps(line)) + "\n")


def capture_job(job_id, shape, rig, size):
    out = f"out/{job_id}"
    return {"id": job_id, "args": ["capture", "--shape", shape, "--rig", rig, "--size", str(size), "--out", out],
            "outputs": [out]}


def staging_entries(folder):
    return sorted(e for e in os.listdir(folder) if ".tmp-" in e)


def process_running(pid):
    """True unless `pid` is gone or a zombie."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


class IbrDaskTest(unittest.TestCase):
    def setUp(self):
        self.work = os.path.join(ARGS.work, self._testMethodName)
        shutil.rmtree(self.work, ignore_errors=True)
        os.makedirs(self.work)
        self.wrapper, self.started = write_wrapper(self.work, ARGS.ibr)

    def ibr_dask(self, *args, **kwargs):
        return subprocess.Popen([sys.executable, ARGS.script, *args, "--ibr", self.wrapper], cwd=self.work,
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kwargs)

    def check_dataset(self, folder, views):
        """A complete capture: dataset.json parses, lists `views` views whose files
        exist, and the ibr marker lists exactly the files there."""
        with open(os.path.join(folder, "dataset.json")) as f:
            dataset = json.load(f)
        self.assertEqual(len(dataset["views"]), views, folder)
        for view in dataset["views"]:
            for kind in ("color", "depth", "mask"):
                self.assertTrue(os.path.isfile(os.path.join(folder, view[kind])), f"{folder}: {view[kind]}")
        with open(os.path.join(folder, ".ibr-output")) as f:
            listed = sorted(f.read().splitlines()[1:])
        present = sorted(os.path.relpath(os.path.join(d, n), folder) for d, _, names in os.walk(folder)
                         for n in names if n != ".ibr-output")
        self.assertEqual(listed, present, folder)
        self.assertEqual(len(present), 1 + 4 * views, folder)  # dataset.json + color, depth, mask, normal

    def test_killed_worker_every_output_once(self):
        manifest = os.path.join(self.work, "jobs.jsonl")
        write_manifest(manifest, [capture_job(i, s, r, n) for i, s, r, n, _ in JOBS])
        out = os.path.join(self.work, "out")
        summary = os.path.join(self.work, "summary.json")
        begin = time.time()
        proc = self.ibr_dask(manifest, "--workers", "2", "--retries", "2", "--summary", summary)

        # Wait until the slow job's ibr has written part of its output into its
        # staging folder, then kill the Dask worker process running it.
        killed_worker = killed_ibr = None
        deadline = time.time() + BATCH_TIMEOUT
        while killed_worker is None and time.time() < deadline and proc.poll() is None:
            starts = [s for s in read_starts(self.started) if f"--out out/{SLOW}" in s[2]]
            staged = [e for e in staging_entries(out) if e.startswith(f".{SLOW}.tmp-")] if os.path.isdir(out) else []
            if starts and staged and any(files for _, _, files in os.walk(os.path.join(out, staged[0]))):
                worker_pid, ibr_pid, _ = starts[0]
                self.assertTrue(process_running(ibr_pid), "the slow ibr ended before the kill")
                os.kill(worker_pid, signal.SIGKILL)
                killed_worker, killed_ibr = worker_pid, ibr_pid
                print(f"killed worker pid {worker_pid} while its ibr (pid {ibr_pid}) was writing "
                      f"{staged[0]} ({time.time() - begin:.1f} s into the batch)", flush=True)
            time.sleep(0.02)
        self.assertIsNotNone(killed_worker, "the slow job never started writing")
        # Its ibr is told (SIGTERM as its parent dies), removes its staging
        # folder and exits at once, rather than running on as an orphan.
        kill_time = time.time()
        while process_running(killed_ibr) and time.time() < kill_time + 5:
            time.sleep(0.02)
        self.assertFalse(process_running(killed_ibr), "the killed worker's ibr still runs")
        self.assertEqual([e for e in staging_entries(out) if e.startswith(f".{SLOW}.tmp-{killed_ibr}-")], [])
        stdout, stderr = proc.communicate(timeout=BATCH_TIMEOUT)
        print(stdout, flush=True)
        self.assertEqual(proc.returncode, 0, stderr)

        # Every output exactly once, complete, and nothing staged left.
        self.assertEqual(sorted(os.listdir(out)), sorted(j[0] for j in JOBS))
        for job_id, _, _, _, views in JOBS:
            self.check_dataset(os.path.join(out, job_id), views)

        # The slow job ran twice: first on the killed worker (lost), then again.
        starts = read_starts(self.started)
        slow_starts = [s for s in starts if f"--out out/{SLOW}" in s[2]]
        self.assertEqual(len(slow_starts), 2, starts)
        self.assertEqual(len(starts), len(JOBS) + 1, starts)
        with open(summary) as f:
            doc = json.load(f)
        jobs = {j["id"]: j for j in doc["jobs"]}
        self.assertEqual(set(jobs), {j[0] for j in JOBS})
        for job in doc["jobs"]:
            self.assertEqual(job["status"], "done", job)
        attempts = jobs[SLOW]["attempts"]
        self.assertEqual([a["outcome"] for a in attempts], ["lost", "done"], attempts)
        self.assertEqual(attempts[0]["pid"], killed_worker)
        finished_before = [j["id"] for j in doc["jobs"] if j["id"] != SLOW and j["attempts"][0]["pid"] == killed_worker]
        self.assertTrue(finished_before, "the killed worker had run no other job")
        for job in doc["jobs"]:
            if job["id"] != SLOW:
                self.assertEqual(len(job["attempts"]), 1, job)  # not run again with its dead worker
        self.assertNotEqual(attempts[1]["pid"], killed_worker)
        self.assertIn(f"retried: {SLOW} attempt 1", stdout)
        retried = sum(len(j["attempts"]) - 1 for j in doc["jobs"])
        print(f"ibr_dask_test: {len(JOBS)} jobs, {retried} retried, batch {doc['wall_seconds']:.1f} s, "
              f"slow job {attempts[1]['seconds']:.1f} s on its re-run", flush=True)

        # Again with --resume: every job is skipped and no output is rewritten;
        # a failing job beside them is retried once and reported (exit 1).
        inodes = {j[0]: os.stat(os.path.join(out, j[0], "dataset.json")).st_ino for j in JOBS}
        failing = {"id": "bad-shape", "args": ["capture", "--shape", "no-such-shape", "--out", "out/bad"],
                   "outputs": ["out/bad"]}
        again = os.path.join(self.work, "again.jsonl")
        write_manifest(again, [capture_job(i, s, r, n) for i, s, r, n, _ in JOBS] + [failing])
        summary2 = os.path.join(self.work, "again.csv")
        proc = self.ibr_dask(again, "--workers", "2", "--retries", "1", "--resume", "--summary", summary2)
        stdout, stderr = proc.communicate(timeout=BATCH_TIMEOUT)
        print(stdout, flush=True)
        self.assertEqual(proc.returncode, 1, stderr)
        self.assertIn("ibr-dask: error: 1 of 9 jobs failed after 1 retries: bad-shape", stderr)
        self.assertIn("no-such-shape", stderr)  # ibr's own error line, kept
        for job_id, inode in inodes.items():
            self.assertEqual(os.stat(os.path.join(out, job_id, "dataset.json")).st_ino, inode, job_id)
        self.assertEqual(sorted(os.listdir(out)), sorted(j[0] for j in JOBS))  # no out/bad, nothing staged
        new_starts = read_starts(self.started)[len(starts):]
        self.assertEqual([s[2].split("--out ")[1] for s in new_starts], ["out/bad", "out/bad"])
        with open(summary2) as f:
            rows = [line.split(",") for line in f.read().splitlines()]
        self.assertEqual(rows[0][:3], ["job", "attempt", "outcome"])
        outcomes = sorted((r[0], r[1], r[2]) for r in rows[1:])
        self.assertEqual(outcomes, sorted([(j[0], "1", "skipped") for j in JOBS] +
                                          [("bad-shape", "1", "failed"), ("bad-shape", "2", "failed")]))

    def test_bad_manifest_runs_nothing(self):
        good = json.dumps(capture_job("a", "box", "cube", 32))
        cases = [
            ([good, '{"args": ["capture", '], 2, "not valid JSON"),
            ([good, "", '["capture"]'], 3, "expected a JSON object"),
            ([good, '{"id": "b"}'], 2, "'args' must be a non-empty list of strings"),
            ([good, '{"args": ["info", 3]}'], 2, "'args' must be a non-empty list of strings"),
            ([good, '{"args": ["info"], "output": ["x"]}'], 2, "unknown key 'output'"),
            ([good, json.dumps(capture_job("a", "box", "cube", 32))], 2, "id 'a' is already used on line 1"),
            ([good, json.dumps(dict(capture_job("b", "box", "cube", 32), outputs=["./out/a"]))], 2,
             "output './out/a' is also written by line 1"),
            ([good, '{"args": ["info"], "cwd": 7}'], 2, "'cwd' must be a non-empty string"),
        ]
        manifest = os.path.join(self.work, "bad.jsonl")
        for lines, line, message in cases:
            with self.subTest(message=message):
                write_manifest(manifest, lines)
                proc = self.ibr_dask(manifest, "--workers", "2")
                stdout, stderr = proc.communicate(timeout=60)
                self.assertEqual(proc.returncode, 2, stderr)
                self.assertEqual(stdout, "")
                self.assertEqual(stderr.splitlines(), [stderr.splitlines()[0]], stderr)  # one line
                self.assertTrue(stderr.startswith(f"ibr-dask: error: {manifest}:{line}: "), stderr)
                self.assertIn(message, stderr)
        write_manifest(manifest, ["", "  "])
        proc = self.ibr_dask(manifest, "--workers", "2")
        _, stderr = proc.communicate(timeout=60)
        self.assertEqual(proc.returncode, 2)
        self.assertIn(f"{manifest}: no jobs", stderr)
        self.assertFalse(os.path.exists(self.started), "a job ran")
        self.assertFalse(os.path.exists(os.path.join(self.work, "out")), "an output was written")


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("--ibr", required=True)
    parser.add_argument("--script", required=True)
    parser.add_argument("--work", required=True)
    ARGS, rest = parser.parse_known_args()
    ARGS.ibr, ARGS.script, ARGS.work = (os.path.abspath(p) for p in (ARGS.ibr, ARGS.script, ARGS.work))
    try:
        import distributed  # noqa: F401  (what scripts/ibr-dask runs on)
    except ImportError:
        sys.exit("ibr_dask_test: python3-distributed is missing: run scripts/install-deps.sh")
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)
