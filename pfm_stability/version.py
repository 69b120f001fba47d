"""The package version, in one place (read by the package root, the CLI's ``--version`` and the build)."""

__all__ = ["__version__"]

__version__ = "0.1.0"
