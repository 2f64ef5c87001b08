"""What the tests of the house-rule scripts share: a script run on a made-up workspace, and a
table of such cases checked for their exit code and a line of their output."""
import subprocess
import sys
import tempfile
from pathlib import Path


def run(script, files):
    """Exit code and output of `script --root DIR` on a workspace holding `files` (path -> text)."""
    with tempfile.TemporaryDirectory() as d:
        for path, text in files.items():
            f = Path(d) / path
            f.parent.mkdir(parents=True, exist_ok=True)
            f.write_text(text)
        p = subprocess.run([sys.executable, str(script), "--root", d], capture_output=True, text=True)
        return p.returncode, p.stdout + p.stderr


def check(script, cases):
    """Runs each (name, files, exit code wanted, text wanted in the output) case; 1 if any fails."""
    passed = failed = 0
    for name, files, want_code, want_text in cases:
        code, out = run(script, files)
        if code == want_code and want_text in out:
            passed += 1
        else:
            failed += 1
            print(f"FAIL {name}: exit {code} (want {want_code}), output:\n{out}")
    print(f"{passed} passed, {failed} failed")
    return 1 if failed else 0
