# asp's STEP converter: STEP bytes on stdin, GLB bytes on stdout (OpenCASCADE through the
# cascadio wheel). Run by asp's Rust loader as `python -c <this file> RELATIVE ANGULAR`; the
# Python package does the same in-process (asp/step.py). Exit codes: 3 cascadio missing,
# 4 OpenCASCADE could not read the file (its own message on stderr).
import os
import sys

# the GLB goes to the original stdout; whatever OpenCASCADE prints goes to stderr
out = os.fdopen(os.dup(1), "wb")
os.dup2(2, 1)
try:
    import cascadio
except ImportError as error:
    sys.stderr.write(f"{error}\n")
    sys.exit(3)

relative, angular = float(sys.argv[1]), float(sys.argv[2])
glb = cascadio.load(
    sys.stdin.buffer.read(),
    file_type="step",
    tol_linear=relative,
    tol_angular=angular,
    tol_relative=True,
    include_brep=True,
    merge_primitives=True,
)
if not glb:
    sys.exit(4)
out.write(glb)
out.close()
