"""Packages and package data of the wheel (the rest of the metadata is in pyproject.toml).

The repository's rules/ (the source of truth, beside its plunit files; rules/lib/
holds the module the rule files share) and checkpoints/ (the curated agents) are
mapped into the package as ``neurosym.rules`` and ``neurosym.checkpoints``: an
installed neurosym finds its rule files and agents without a clone, and nothing
is copied in the repository.
The Prolog modules of the janus bridge (neurosym/prolog/pl/*.pl) ship as
package data; their plunit files (*.plt) stay behind.
"""

from setuptools import find_packages, setup

setup(
    packages=[
        *find_packages(include=["neurosym", "neurosym.*"]),
        "neurosym.rules",
        "neurosym.checkpoints",
    ],
    package_dir={"neurosym.rules": "rules", "neurosym.checkpoints": "checkpoints"},
    package_data={
        "neurosym": ["setup_swipl.sh"],  # `neurosym setup-prolog` builds SWI-Prolog with it
        "neurosym.envs": ["maps/*.txt"],
        "neurosym.prolog": ["pl/*.pl"],  # the bridge's Prolog modules (not their .plt tests)
        "neurosym.induce": ["pl/*.pl"],  # the Prolog text learned files carry
        "neurosym.play": [
            "pl/*.pl",
            "strategies/*.pl",
        ],  # neurosym play's Prolog, --compare's strategies
        "neurosym.reports.web": ["templates/*"],
        "neurosym.rules": ["*.pl", "lib/*.pl"],
        "neurosym.checkpoints": ["*.pt"],
    },
    exclude_package_data={"neurosym.rules": ["tests/*"]},
)
