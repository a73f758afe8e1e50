"""Prints where the edmodel package goes under an install prefix, relative to it.

Usage: python3 edmPythonDestination.py PREFIX

The interpreter's own site directories under PREFIX come first (Debian's
python3 searches /usr/local/lib/python3.X/dist-packages for the prefix
/usr/local and /usr/lib/python3/dist-packages for /usr); for any other prefix,
the sysconfig platlib of the posix_prefix scheme (lib/python3.X/site-packages),
which PYTHONPATH must then name.
"""

import os
import site
import sys
import sysconfig

prefix = os.path.abspath(sys.argv[1])
candidates = []
if hasattr(site, "getsitepackages"):
    candidates += site.getsitepackages()
candidates += sys.path
for path in candidates:
    if not path or not os.path.isabs(path):
        continue
    relative = os.path.relpath(os.path.abspath(path), prefix)
    # Directly under PREFIX/lib (not under another prefix below this one).
    if relative.startswith("lib" + os.sep) and os.path.basename(relative) in ("site-packages", "dist-packages"):
        print(relative)
        sys.exit(0)
platlib = sysconfig.get_path("platlib", "posix_prefix", vars={"base": prefix, "platbase": prefix})
print(os.path.relpath(platlib, prefix))
