# The public names of rough.reports, loaded on first use by lazy_loader (see __init__.py).
from .choices import FORMATS as FORMATS
from .choices import SETS as SETS
from .rendering import load_template as load_template
from .rendering import render_html as render_html
from .rendering import render_pdf as render_pdf
from .rendering import summaries as summaries
from .sections import Section as Section
from .sections import surface_section as surface_section
from .writing import format_of as format_of
from .writing import settings_text as settings_text
from .writing import write_report as write_report
from .writing import write_sections as write_sections
