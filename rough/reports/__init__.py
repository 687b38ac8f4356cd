"""Reports a lab can hand on: ``rough report`` as a library.

:func:`write_report` reads surfaces (or takes them), evaluates each as ``rough
features`` does (form removed and filter as asked), fits its spectrum and, for a map,
its rose, draws the figures, and writes one self-contained HTML page (figures as
``data:`` URIs, inline style and script) or a PDF of the same page (WeasyPrint). The
steps are public too: :func:`surface_section` makes the :class:`Section` of one
surface, :func:`render_html` lays sections out through a Jinja2 template (the
default one, or a lab's own), :func:`render_pdf` prints that HTML.
"""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
