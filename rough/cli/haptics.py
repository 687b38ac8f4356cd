"""Options shared by the commands that drive a haptic device (render, experiment run):
the device, the contact and friction models, the servo loop's settings, the stability
check."""

import dataclasses
import functools
import logging

import click

from .. import extras, render
from .options import SPACING, QuantityType

MAX_RATE = 100e3  # Hz: a Python tick takes a few microseconds; no device or model needs more


class PositiveQuantity(QuantityType):
    """A quantity that must be positive (and at most ``most``, if given)."""

    def __init__(self, kind, default_unit, most=None):
        super().__init__(kind, default_unit, positive=True, most=most)


FORCE, STIFFNESS, DAMPING = (
    QuantityType("force", "N"),
    PositiveQuantity("stiffness", "N/mm"),
    QuantityType("damping", "N*s/m"),
)
MASS, SPEED, TIME, RATE = (
    PositiveQuantity("mass", "g"),
    PositiveQuantity("speed", "mm/s"),
    PositiveQuantity("time", "s"),
    PositiveQuantity("rate", "Hz", most=MAX_RATE),
)
MAX_FORCE = PositiveQuantity("force", "N")
RAMP = QuantityType("time", "s")


class DeviceOption(click.Option):
    """``--device``, whose forms and help come from the registry of devices
    (:func:`rough.render.backends`, plugins included) when the help is shown."""

    @property
    def metavar(self):
        return "|".join(backend.form for backend in render.backends().values())

    @metavar.setter
    def metavar(self, value):
        pass

    @property
    def help(self):
        return f"{render.descriptions()}. After the colon: which one (default: the first found)."

    @help.setter
    def help(self, value):
        pass


class CouplingType(click.ParamType):
    """``K,B``: the virtual coupling's stiffness and damping → (N/m, N·s/m)."""

    name = "K,B"

    def convert(self, value, param, ctx):
        if isinstance(value, tuple):
            return value
        parts = value.split(",")
        if len(parts) != 2:
            self.fail(f"{value!r}: give K,B, e.g. 0.8N/mm,0N*s/m", param, ctx)
        return STIFFNESS.convert(parts[0], param, ctx), DAMPING.convert(parts[1], param, ctx)


@dataclasses.dataclass(frozen=True)
class Haptics:
    """The device and loop options as given (SI units)."""

    device: str
    rate: float
    model: str
    stiffness: float
    mass: float
    damping: float
    friction: str
    max_force: float
    stick_span: tuple
    invert: tuple
    ramp: float
    velocity_filter: float
    watchdog: float
    priority: int
    coupling: tuple
    device_damping: float

    @property
    def simulated(self):
        return render.is_simulated(self.device)

    def contact(self):
        """The profile's contact model, behind the virtual coupling if one was asked for."""
        model = render.make_model(self.model, self.stiffness, self.mass, self.damping, 1.0 / self.rate)
        if self.coupling is None:
            return model
        if self.model != "quasi-static":
            raise click.BadParameter("the virtual coupling wraps the quasi-static model", param_hint="--coupling")
        return render.VirtualCoupling(model, *self.coupling, period=1.0 / self.rate)

    def field(self, load):
        """The map's gradient field with the normal load ``load`` (N)."""
        if self.model != "quasi-static" or self.coupling is not None:
            raise click.BadParameter(
                "a map is felt through the lateral gradient field; --model dynamic and --coupling apply to profiles",
                param_hint="--model/--coupling",
            )
        return render.GradientField(load)

    def device_model(self, contact, load, device):
        """``contact`` as the open ``device`` renders it (a wheel feels a profile's
        lateral force alone, with the normal load ``load``, N), checked against the
        passivity bound when it is a contact model."""
        model = render.fitted_model(contact, device, load)
        if model is contact and hasattr(contact, "stiffness"):
            self.warn_if_unstable()
        return model

    def warn_if_unstable(self, damping=None):
        """Log one warning when the contact stiffness exceeds the passivity bound at
        this rate for a device of damping ``damping`` (N·s/m; default
        ``--device-damping``) and no coupling holds it."""
        b = self.device_damping if damping is None else damping
        message = render.stability_warning(self.stiffness, self.rate, b, self.coupling)
        if message:
            logging.getLogger("rough").warning(message)

    def friction_model(self):
        return render.parse_friction(self.friction)

    def settings(self, duration=None, realtime=False):
        ramp = self.ramp if self.ramp is not None else (0.0 if self.simulated else 0.5)
        return render.Settings(
            rate=self.rate,
            duration=duration,
            max_force=self.max_force,
            velocity_cutoff=self.velocity_filter,
            watchdog=self.watchdog,
            priority=self.priority,
            ramp=ramp,
            realtime=realtime or not self.simulated,
        )


def haptic_options(command):
    """Adds the device, model and loop options; the command receives ``haptics``."""
    names = [field.name for field in dataclasses.fields(Haptics)]

    @functools.wraps(command)
    def wrapper(*args, **kwargs):
        values = {name: kwargs.pop(name) for name in names}
        try:
            backend, _ = render.parse_device(values["device"])
        except render.DeviceError as error:
            raise click.BadParameter(str(error).partition(": ")[2], param_hint="--device") from None
        for module in render.backends()[backend].requires:
            extras.require(module)
        return command(*args, haptics=Haptics(**values), **kwargs)

    options = [
        click.option(
            "--device",
            cls=DeviceOption,
            default="sim",
            show_default=True,
        ),
        click.option("--rate", type=RATE, default="1kHz", show_default=True, help="Servo rate."),
        click.option(
            "--model",
            type=click.Choice(["quasi-static", "dynamic"]),
            default="quasi-static",
            show_default=True,
            help="quasi-static: F = K·penetration (M, C negligible); dynamic: the stylus with mass and damping.",
        ),
        click.option("--stiffness", type=STIFFNESS, default="1.28N/mm", show_default=True, help="Contact stiffness K."),
        click.option(
            "--mass",
            type=MASS,
            default="1.85g",
            show_default=True,
            help="dynamic: stylus mass M (the slides' 1.85e-6 read in N·s²/mm = 1.85 g; docs: Mathematics §5.3).",
        ),
        click.option(
            "--damping", type=DAMPING, default="4.6e-5N*s/mm", show_default=True, help="dynamic: stylus damping C."
        ),
        click.option(
            "--friction",
            metavar="MODEL[:k=v,...]",
            help="coulomb:level=0.3N,viscous=2N*s/m | karnopp:static=0.8N,coulomb=0.5N,band=2mm/s,stiffness=1N/mm | "
            "dahl:stiffness=1N/mm,coulomb=0.5N (default none).",
        ),
        click.option(
            "--max-force",
            type=MAX_FORCE,
            default="8.9N",
            show_default=True,
            help="Device maximum; the force vector is scaled to it.",
        ),
        click.option(
            "--stick-span",
            type=SPACING,
            metavar="X,Y",
            help="Joysticks: lengths the stick's full x and y travel cover (default: the window, and 4× the "
            "profile's height range; on a map, the map's extent).",
        ),
        click.option(
            "--invert",
            type=click.Choice(["x", "y"]),
            multiple=True,
            help="Joysticks: reverse an axis (position and force).",
        ),
        click.option(
            "--ramp",
            type=RAMP,
            help="Ramp the force in over this time at the start (default: joysticks 0.5 s, sim none).",
        ),
        click.option(
            "--velocity-filter",
            type=RATE,
            default="100Hz",
            show_default=True,
            help="Cut-off of the velocity estimate's low-pass filter.",
        ),
        click.option(
            "--watchdog",
            type=TIME,
            default="10ms",
            show_default=True,
            help="Joysticks: zero the force if the loop stalls this long.",
        ),
        click.option(
            "--priority",
            type=click.IntRange(0, 99),
            default=50,
            show_default=True,
            help="Real-time loops: run at SCHED_FIFO priority N where permitted (0: normal scheduling).",
        ),
        click.option(
            "--coupling",
            type=CouplingType(),
            help="Render the quasi-static contact through a virtual coupling of stiffness K and damping B (e.g. "
            "0.8N/mm,0N*s/m), which keeps it passive when K T/2 + B stays below the device's damping.",
        ),
        click.option(
            "--device-damping",
            type=DAMPING,
            default="0.45N*s/m",
            show_default=True,
            help="Joysticks: the device's own damping b, for the passivity bound K ≤ 2b/T (Colgate & Schenkel); "
            "the default is an assumption that puts the bound at 0.9 N/mm at 1 kHz, near the stiffness Choi & Tan "
            "rendered cleanly. Measure your device's b and give it here. The simulated hand uses --hand-damping.",
        ),
    ]
    for option in reversed(options):
        wrapper = option(wrapper)
    return wrapper
