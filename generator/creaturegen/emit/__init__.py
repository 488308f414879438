"""Emit: render a plain build plan through Jinja templates into out/<slug>/, atomically."""

from .writer import PackageFile, PackageWriteError, header_for, write_package

__all__ = ["PackageFile", "PackageWriteError", "header_for", "write_package"]
