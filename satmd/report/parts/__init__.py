"""The parts of the report `satmd reproduce` writes: one module a section, listed by `satmd.report.sections()`.

Each module has ``ORDER`` (its place), ``TITLE`` and ``run(ctx)``, which returns the section's markdown;
its key for ``reproduce(only=...)`` is the module's name (``forward``, ``identify``, ``f16``, ...).
"""
