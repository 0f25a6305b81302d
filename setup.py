"""Packaging beyond what ``pyproject.toml`` can say: one namespace, and the shipped assemblies.

Installed, everything stands under ``assembly_constraints``: the repository's layers
``asp/``, ``executor/`` and ``bridge/`` are ``assembly_constraints.asp``, ``.executor`` and
``.bridge`` (in the checkout, ``assembly_constraints/`` holds them as symbolic links, so the
same import names work from the repository and from the wheel). The assemblies in ``data/``
(beside the code, where the docs and tests name them) are the package data
``assembly_constraints/bridge/assemblies``, where :data:`assembly_constraints.bridge.assembly.DATA_DIR`
finds them. Everything else is in ``pyproject.toml``.
"""

from setuptools import find_packages, setup

SHIPPED_ASSEMBLIES = "assembly_constraints.bridge.assemblies"

setup(
    packages=[*find_packages(include=["assembly_constraints*"]), SHIPPED_ASSEMBLIES],
    package_dir={SHIPPED_ASSEMBLIES: "data"},
    package_data={
        "": ["py.typed"],
        "assembly_constraints.asp": ["encodings/*.lp", "encodings/*/*.lp"],
        SHIPPED_ASSEMBLIES: ["*/*.*", "*/*/*.*"],
    },
)
