#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Makes the installable wheel of the settle package from the built package directory, offline,
with Debian's tools only (python3-pip, python3-setuptools, python3-wheel; no download, no build
isolation). The wheel is for the interpreter that runs this script (its ABI tag: the extension is
compiled for that interpreter's version) and needs numpy at run time.
  make_wheel.py --package DIR --version X.Y.Z --license FILE --out DIR
DIR holds settle/ (__init__.py, __init__.pyi, py.typed, the _settle extension)."""
import argparse
import pathlib
import shutil
import subprocess
import sys
import tempfile

SETUP = '''# SPDX-License-Identifier: Apache-2.0
from setuptools import setup
from setuptools.dist import Distribution


class BinaryDistribution(Distribution):
    """The package carries a compiled extension: a platform wheel, never a pure one."""

    def has_ext_modules(self):
        return True


setup(
    name="settle",
    version={version!r},
    description="Vibration-free point-to-point moves: planning, sampling, simulation",
    long_description=open("README.txt").read(),
    long_description_content_type="text/plain",
    license="Apache-2.0",
    license_files=["LICENSE"],
    classifiers=[
        "License :: OSI Approved :: Apache Software License",
        "Programming Language :: Python :: 3",
        "Programming Language :: C++",
        "Typing :: Typed",
    ],
    packages=["settle"],
    package_data={{"settle": ["_settle*.so", "__init__.pyi", "py.typed"]}},
    python_requires=">={major}.{minor}",
    install_requires=["numpy"],
    distclass=BinaryDistribution,
    zip_safe=False,
)
'''

PYPROJECT = '''[build-system]
requires = ["setuptools", "wheel"]
build-backend = "setuptools.build_meta"
'''

README = '''settle: Settle's planner and simulator for Python (import settle).
Every function takes the move as keywords, the settle CLI's options without their dashes;
see help(settle) and the typed signatures in settle/__init__.pyi.
'''


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--package", required=True, type=pathlib.Path)
    ap.add_argument("--version", required=True)
    ap.add_argument("--license", required=True, type=pathlib.Path)
    ap.add_argument("--out", required=True, type=pathlib.Path)
    a = ap.parse_args()
    src = a.package / "settle"
    if not list(src.glob("_settle*.so")):
        sys.exit(f"make_wheel: no built extension (_settle*.so) in {src}")
    a.out.mkdir(parents=True, exist_ok=True)
    for old in a.out.glob("settle-*.whl"):
        old.unlink()
    with tempfile.TemporaryDirectory(prefix="settle-wheel-") as tmp:
        stage = pathlib.Path(tmp)
        shutil.copytree(src, stage / "settle", ignore=shutil.ignore_patterns("__pycache__"))
        shutil.copy(a.license, stage / "LICENSE")
        (stage / "README.txt").write_text(README)
        (stage / "pyproject.toml").write_text(PYPROJECT)
        v = sys.version_info
        (stage / "setup.py").write_text(SETUP.format(version=a.version, major=v.major, minor=v.minor))
        cmd = [sys.executable, "-m", "pip", "wheel", "--no-index", "--no-build-isolation", "--no-deps",
               "--quiet", "--wheel-dir", str(a.out), str(stage)]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit(f"make_wheel: pip wheel failed ({r.returncode}):\n{r.stdout}{r.stderr}")
    wheels = list(a.out.glob("settle-*.whl"))
    if len(wheels) != 1:
        sys.exit(f"make_wheel: expected one wheel in {a.out}, found {wheels}")
    print(wheels[0])


if __name__ == "__main__":
    main()
