"""Build step that pyproject.toml cannot declare: ship the top-level shaders/ and fabrics/
folders inside the package, as catalog/_data/shaders and catalog/_data/fabrics, so an
installed wheel finds them through importlib.resources (catalog.core.resources). The
folders stay where they are in the repository; an editable install reads them in place."""

import shutil
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

ROOT = Path(__file__).resolve().parent
SHIPPED = ("shaders", "fabrics")


class BuildPyWithData(build_py):
    def run(self):
        super().run()
        if getattr(self, "editable_mode", False):
            return  # editable: catalog.core.resources falls back to the checkout's folders
        for name in SHIPPED:
            target = Path(self.build_lib) / "catalog" / "_data" / name
            shutil.rmtree(target, ignore_errors=True)
            shutil.copytree(ROOT / name, target,
                            ignore=shutil.ignore_patterns("__pycache__", "*.pyc", ".*"))


setup(cmdclass={"build_py": BuildPyWithData})
