"""The Masing/Iwan friction element: a plain C99 core (``core/``), its FMI 2.0 and
3.0 co-simulation wrappers, and the one small Python module that reaches the core
with numpy arrays (``fmu_src.element``)."""
