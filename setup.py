"""Packaging beyond what ``pyproject.toml`` can say: the four packages, and the shipped assemblies.

The repository's folders are the packages Python imports, installed as they stand: the
front ``assembly_constraints`` (console command, Python API) and the layers ``asp``,
``executor`` and ``bridge`` (``docs/decisions.md`` says why top-level). The assemblies in
``data/`` (beside the code, where the docs and tests name them) are the package data
``bridge/assemblies``, where :data:`bridge.assembly.DATA_DIR` finds them. Folders without
Python modules (``asp/encodings``, each assembly's ``assets/``) are data of the package above
them, listed in ``package_data`` and nowhere else: with ``include_package_data`` off,
setuptools takes no file from its manifest, so it does not ask for them as packages.
Everything else is in ``pyproject.toml``.
"""

from setuptools import find_packages, setup

LAYERS = ["asp", "executor", "bridge"]
SHIPPED_ASSEMBLIES = "bridge.assemblies"

setup(
    packages=[*find_packages(include=[name for package in ("assembly_constraints", *LAYERS)
                                      for name in (package, f"{package}.*")]),
              SHIPPED_ASSEMBLIES],
    package_dir={SHIPPED_ASSEMBLIES: "data"},
    include_package_data=False,  # the data is exactly package_data below
    package_data={
        "": ["py.typed"],
        "asp": ["encodings/*.lp", "encodings/*/*.lp"],
        SHIPPED_ASSEMBLIES: ["*/*.*", "*/*/*.*"],
    },
)
