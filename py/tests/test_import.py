"""`import asp` needs numpy and nothing else: not torch, not onnx."""

from __future__ import annotations

import subprocess
import sys

import asp

BLOCK = """
import sys
class Blocker:
    def find_spec(self, name, path=None, target=None):
        if name.split('.')[0] in ('torch', 'onnx', 'onnxruntime'):
            raise ImportError('blocked for the test: ' + name)
sys.meta_path.insert(0, Blocker())
"""


def run(code: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", BLOCK + code], capture_output=True, text=True, timeout=120)


def test_import_asp_without_torch():
    p = run(
        "import asp\n"
        "a = asp.Assembly\n"
        "assert 'torch' not in sys.modules and 'onnx' not in sys.modules\n"
        "print(asp.__version__, len(asp.ORDERS))\n"
    )
    assert p.returncode == 0, p.stderr
    assert p.stdout.split()[0] == asp.__version__


def test_the_blocker_blocks():
    # the test above would pass vacuously if blocking did not work
    p = run("import torch\n")
    assert p.returncode != 0 and "blocked for the test" in p.stderr


def test_public_api():
    for name in asp.__all__:
        assert hasattr(asp, name), name
    assert issubclass(asp.LoadError, asp.AspError) and issubclass(asp.ConfigError, asp.AspError)
    assert asp.PLAN_FORMAT_VERSION
    assert asp._asp.__name__ == "asp._asp"
