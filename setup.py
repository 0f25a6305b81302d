"""Packaging beyond what ``pyproject.toml`` can say: one namespace, and the shipped assemblies.

Installed, everything stands under ``assembly_constraints``: the repository's layers
``asp/``, ``executor/`` and ``bridge/`` are ``assembly_constraints.asp``, ``.executor`` and
``.bridge`` (in the checkout, ``assembly_constraints/`` holds them as symbolic links, so the
same import names work from the repository and from the wheel). The assemblies in ``data/``
(beside the code, where the docs and tests name them) are the package data
``assembly_constraints/bridge/assemblies``, where :data:`assembly_constraints.bridge.assembly.DATA_DIR`
finds them. Folders without Python modules (``asp/encodings``, each assembly's ``assets/``)
are data of the package above them, listed in ``package_data`` and nowhere else: with
``include_package_data`` off, setuptools takes no file from its manifest, so it does not ask for
them as packages. Everything else is in ``pyproject.toml``.
"""

from setuptools import find_packages, setup

SHIPPED_ASSEMBLIES = "assembly_constraints.bridge.assemblies"

setup(
    packages=[*find_packages(include=["assembly_constraints*"]), SHIPPED_ASSEMBLIES],
    package_dir={SHIPPED_ASSEMBLIES: "data"},
    include_package_data=False,  # the data is exactly package_data below
    package_data={
        "": ["py.typed"],
        "assembly_constraints.asp": ["encodings/*.lp", "encodings/*/*.lp"],
        SHIPPED_ASSEMBLIES: ["*/*.*", "*/*/*.*"],
    },
)
