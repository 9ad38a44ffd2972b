"""The Masing/Iwan friction element: a plain C99 core (``core/``), its FMI 2.0 and
3.0 co-simulation wrappers (``fmi/``: a model-agnostic FMI layer and the element as
one model behind it), and the Python side: ``_clib`` (the one typed ctypes layer),
``element`` / ``element_batch`` (the core with numpy arrays), ``curve_fit`` (curve
diagnosis and reduction to the element's limit), ``fmu_build`` / ``fmu_xml`` (the
packager)."""
