"""Packaging beyond what ``pyproject.toml`` can say: the shipped assemblies.

The repository keeps its assemblies in ``data/`` (beside the code, where the docs and
tests name them); an installed copy carries them as the package data ``bridge/assemblies``,
where :data:`bridge.assembly.DATA_DIR` finds them. Everything else is in ``pyproject.toml``.
"""

from setuptools import find_packages, setup

SHIPPED_ASSEMBLIES = "bridge.assemblies"

setup(
    packages=[*find_packages(include=["assembly_constraints*", "asp*", "executor*", "bridge*"]), SHIPPED_ASSEMBLIES],
    package_dir={SHIPPED_ASSEMBLIES: "data"},
    package_data={
        "": ["py.typed"],
        "asp": ["encodings/*.lp", "encodings/*/*.lp"],
        SHIPPED_ASSEMBLIES: ["*/*.*", "*/*/*.*"],
    },
)
