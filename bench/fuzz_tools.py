"""What the fuzz scripts share: the binaries they run and meshcheck's verdict on a mesh."""
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
PIC = os.environ.get("PIC", os.path.join(HERE, "..", "build", "pic"))
SHARED = os.path.join(HERE, "..", "..", "shared", "tools")
MESHCHECK = os.environ.get("MESHCHECK", os.path.join(SHARED, "build", "meshcheck"))
SCAD_MJS = os.path.join(SHARED, "manifold", "scad.mjs")


def meshcheck(path, exact=True):
    """meshcheck's JSON for a mesh file (`exact`: with the exact self-intersection test), or
    None when it gives none."""
    args = [MESHCHECK, path] + ([] if exact else ["--no-si"])
    try:
        p = subprocess.run(args, capture_output=True, text=True, timeout=600)
        return json.loads(p.stdout) if p.returncode == 0 and p.stdout.strip() else None
    except (subprocess.SubprocessError, ValueError, OSError):
        return None


def arguments(usage, depth, out):
    """FIRST_SEED COUNT [DEPTH] [OUTDIR] from the command line, with these defaults; `usage`
    (the script's docstring) and exit without the first two."""
    if len(sys.argv) < 3:
        sys.exit(usage)
    return (int(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3]) if len(sys.argv) > 3 else depth,
            sys.argv[4] if len(sys.argv) > 4 else out)
