"""The addon's version, also the version its native core must report (native_core/CMakeLists.txt and
pyproject.toml read it from here)."""
__version__ = "0.2.0"
