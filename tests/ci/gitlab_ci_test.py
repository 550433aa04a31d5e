#!/usr/bin/env python3
"""Runs the script lines of ci/gitlab-ci.yml as GitLab would, with the variables it sets.

Usage: gitlab_ci_test.py SOURCE_DIR RASTERCHECK

Every job with a `script`, in the order of `stages`; a job with `parallel: N` runs N times
with CI_NODE_INDEX 1..N and CI_NODE_TOTAL N, as GitLab's parallel jobs do. Each line runs
in bash from CI_PROJECT_DIR (a scratch copy of ci/), with the template's variables, except
three the test sets: the command under test (not one `before_script` would build), a small
part of the catalog and llvmpipe alone, to stay quick. A job fails when a line exits
non-zero, as in GitLab. Then: the merged report holds every part's rows once and matches
the baseline; and a baseline line the run contradicts makes the report job fail.
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile

import yaml


def run_jobs(doc, work, variables, only=None):
    """Runs every job (or those in `only`); returns {job name: [exit codes]}."""
    codes = {}
    for stage in doc.get("stages", ["test"]):
        for name, job in doc.items():
            if not isinstance(job, dict) or "script" not in job:
                continue
            if job.get("stage", "test") != stage or (only and name not in only):
                continue
            total = int(job.get("parallel", 1))
            for index in range(1, total + 1):
                env = dict(os.environ)
                env.update({k: str(v) for k, v in variables.items()})
                env.update({"CI": "true", "GITLAB_CI": "true", "CI_PROJECT_DIR": work,
                            "CI_JOB_STAGE": stage,
                            "CI_JOB_NAME": f"{name} {index}/{total}" if total > 1 else name})
                if "parallel" in job:
                    env.update({"CI_NODE_INDEX": str(index), "CI_NODE_TOTAL": str(total)})
                code = 0
                for line in job["script"]:
                    r = subprocess.run(["bash", "-c", line], cwd=work, env=env,
                                       capture_output=True, text=True)
                    if r.returncode != 0:
                        code = r.returncode
                        print(f"{name} {index}/{total}: `{line}` exited {code}:\n{r.stdout}{r.stderr}")
                        break
                codes.setdefault(name, []).append(code)
    return codes


def main():
    source, exe = sys.argv[1], sys.argv[2]
    with open(os.path.join(source, "ci", "gitlab-ci.yml")) as f:
        doc = yaml.safe_load(f)
    variables = dict(doc["variables"])
    for key in ("RASTERCHECK", "RASTERCHECK_FIXTURES", "RASTERCHECK_BACKENDS",
                "RASTERCHECK_BASELINE", "RASTERCHECK_FLAKES", "RASTERCHECK_SKIPS"):
        assert key in variables, f"the template lost its variable {key}"
    variables["RASTERCHECK"] = exe
    variables["RASTERCHECK_FIXTURES"] = " ".join(
        os.path.join(source, "fixtures", "scenes", d) for d in ("coverage", "culling"))
    variables["RASTERCHECK_BACKENDS"] = "gl:egl:llvmpipe"
    failures = []

    with tempfile.TemporaryDirectory(prefix="rc_gitlab_ci_") as work:
        shutil.copytree(os.path.join(source, "ci"), os.path.join(work, "ci"))
        codes = run_jobs(doc, work, variables)
        parts = int(doc["rastercheck"]["parallel"])
        if codes.get("rastercheck") != [0] * parts:
            failures.append(f"the shard jobs exited {codes.get('rastercheck')}")
        if codes.get("rastercheck-report") != [0]:
            failures.append(f"the report job exited {codes.get('rastercheck-report')}")
        merged = os.path.join(work, "results", "merged")
        names = []
        for k in range(1, parts + 1):
            with open(os.path.join(work, "results", f"part-{k}", "results.csv")) as f:
                names += [line.split(",")[0] for line in f if line.strip()]
        with open(os.path.join(merged, "results.csv")) as f:
            merged_names = [line.split(",")[0] for line in f if line.strip()]
        if sorted(names) != merged_names or len(set(names)) != len(names) or not names:
            failures.append(f"merged results.csv ({len(merged_names)} tests) is not the parts' "
                            f"{len(names)} tests, each once, sorted")
        with open(os.path.join(merged, "report.json")) as f:
            report = json.load(f)
        if not report.get("runner", {}).get("matches_baseline"):
            failures.append(f"merged report.json runner: {report.get('runner')}")
        if not os.path.exists(os.path.join(merged, "junit.xml")):
            failures.append("no merged junit.xml")

        # A baseline the run contradicts: the first test listed as failing, which passes.
        with open(os.path.join(work, variables["RASTERCHECK_BASELINE"]), "a") as f:
            f.write(f"{merged_names[0]},Fail\n")
        codes = run_jobs(doc, work, variables, only={"rastercheck-report"})
        if codes.get("rastercheck-report") != [1]:
            failures.append(f"with a contradicted baseline the report job exited "
                            f"{codes.get('rastercheck-report')}, not 1")
        with open(os.path.join(merged, "failures.csv")) as f:
            if f.read() != f"{merged_names[0]},UnexpectedPass\n":
                failures.append("failures.csv does not name the unexpected pass")

    for f in failures:
        print("FAIL:", f)
    if not failures:
        print(f"PASS: {parts} parallel jobs and the report job ran as GitLab runs them")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
