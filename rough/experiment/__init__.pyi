# The public names of rough.experiment, loaded on first use by lazy_loader (see __init__.py).
from .analysis import answers_table as answers_table
from .analysis import fit as fit
from .analysis import proportion_interval as proportion_interval
from .design import COSTA2000 as COSTA2000
from .design import grid_design as grid_design
from .design import is_name as is_name
from .design import load_study as load_study
from .design import subject_ids as subject_ids
from .design import write_study as write_study
from .observer import parse_observer as parse_observer
from .session import Keyboard as Keyboard
from .session import joystick_presenter as joystick_presenter
from .session import run_session as run_session
from .session import simulated_presenter as simulated_presenter
