"""The library behind each command: which functions a command calls, so that each of
its options is a keyword of one of them, with the same name (``-`` read as ``_``),
default and unit (SI), and a notebook user can do what the command does
(``tests/test_api_parity.py`` holds every command to this table). The functions are
named as ``module:attribute`` strings, as :data:`rough.cli.main.COMMANDS` names the
commands, so that the table loads nothing (``rough --help`` stays free of numpy).
"""

_READING = ("rough.io:read", "rough.io:open_surface")
_FILES = ("rough.tasks:map_ordered",)  # --jobs/--scheduler over several inputs
_FRACTAL_MODEL = ("rough.fractal:fit_fractal", "rough.fractal:fit_profiles")
_HAPTICS = ("rough.render:Settings", "rough.render:DynamicStylus", "rough.render:open_joystick")

#: Command (``experiment`` subcommands as ``"experiment design"``) → the library
#: callables whose keywords its options are. A class stands for its constructor.
LIBRARY = {
    "info": (*_READING, "rough.metrology:summary"),
    "convert": (*_READING, *_FILES, "rough.io:write"),
    "formats": (),
    "detrend": (*_READING, *_FILES, "rough.metrology:detrend", "rough.io:write"),
    "features": (*_READING, *_FILES, "rough.metrology:parameters", "rough.metrology:detect_features"),
    "synth": (
        "rough.fractal:synthesize_profile",
        "rough.fractal:synthesize_map",
        "rough.fractal:synthesize_fragments",
        "rough.io:write",
    ),
    "fit-fractal": (*_READING, *_FILES, *_FRACTAL_MODEL, "rough.fractal:hurst_exponents"),
    "resample": (*_READING, *_FILES, "rough.fractal:resample", "rough.io:write"),
    "rose": (*_READING, *_FILES, "rough.fractal:rose", "rough.fractal:profile_rose"),
    "show": (*_READING, *_FILES, "rough.plot:surface", "rough.plot:save"),
    "render": (*_READING, *_HAPTICS, "rough.render:simulate", "rough.render:Track.from_surface"),
    "experiment design": ("rough.experiment:grid_design", "rough.experiment:write_study"),
    "experiment run": (*_HAPTICS, "rough.experiment:run_session", "rough.experiment:simulated_presenter"),
    "experiment analyze": ("rough.experiment:answers_table", "rough.experiment:fit"),
    "map": (*_READING, "rough.metrology:roughness_map"),
    "report": (*_READING, "rough.reports:write_report", "rough.reports:surface_section"),
}

#: Options about the command line itself, with no library meaning: option → why.
COMMAND_LINE = {
    "json": "prints the report as JSON; the library returns the values",
    "tsv": "prints the report as TSV; the library returns the values",
    "output": "the file the command writes; the library returns the surface (rough.io.write writes it)",
    "plot": "the figure's file; rough.plot draws the figure and rough.plot.save writes it",
    "psd": "a file for the binned spectrum that rough.fractal.binned_spectrum returns",
    "list": "a file for the features that rough.metrology.detect_features returns",
    "segments": "a file for the hills and dales that rough.metrology.segment returns",
    "trace": "a file for the run's trace, which rough.render.write_trace writes",
    "quiet": "what reaches standard error; a global option (rough.cli.main.GLOBAL_OPTIONS), also before the command",
    "verbose": "notes on standard error; a global option (rough.cli.main.GLOBAL_OPTIONS)",
    "debug": "tracebacks with errors; a global option (rough.cli.main.GLOBAL_OPTIONS)",
}

#: Options whose keyword has another name, or that stand for a call: ``"command --option"``
#: (``"--option"`` alone for every command) → ``"keyword — why"`` or ``"module:callable — why"``.
KEYWORDS = {
    "--ignore-checksums": "verify — a negative flag on the command line; verify=False in Python",
    "detrend --tip": "rough.metrology:traced — the surface as this tip traces it (a preset or a radius)",
    "detrend --envelope": "rough.metrology:closing_envelope — the closing envelope of a disc of this radius",
    "features --detect-cutoff": "cutoff — detect_features' cut-off; --cutoff is the evaluation's",
    "features --detect-mode": "mode — detect_features' mode, named beside --detect-cutoff",
    "features --vs-length": "rough.metrology:rq_versus_length — a flag that adds this function's result",
    "fit-fractal --profiles": "direction — fit_profiles' direction: the flag says what is fitted",
    "fit-fractal --estimator": "estimators — hurst_exponents takes several; --estimator all names them",
    "rose --angle-step": "step — the sector step (degrees), named apart from a grid's --step",
    "rose --profiles": "rough.fractal:profile_rose — a flag that adds the profiles' rose",
    "synth --length": "points — a profile's length, points × step",
    "synth --size": "points — a map's points, as NXxNY",
    "synth --step": "spacing — the sample spacing, named as resample's --step",
    "synth --rolloff-wavelength": "rolloff — the roll-off's wavelength, metres",
    "synth --fragments": "rough.fractal:synthesize_fragments — a flag that synthesises in fragments",
    "resample --step": "spacing — the new sample spacing",
    "render --hand-stiffness": "lateral_stiffness — simulate's stiffness holding the hand to its stroke",
    "render --fill": "rough.fractal:fill_invalid — a flag: the track is filled first",
    "render --tip": "rough.metrology:traced — the track as this tip traces it",
    "experiment design --reference": "references — given once per reference surface",
    "experiment design --step": "spacing — the surfaces' sample spacing",
    "experiment design --synthesis-step": "synthesis_spacing — the spacing they are synthesised at",
    "experiment run --stroke": "rough.render:Stroke — how long the simulated hand strokes each surface",
    "experiment analyze --set": "set_id — the answers of one set",
    **{
        f"{command} --{option}": target
        for command in ("render", "experiment run")
        for option, target in {
            "device": "rough.render:open_device — the device's spec, opened by this function",
            "velocity-filter": "velocity_cutoff — Settings' cut-off of the velocity estimate's filter",
            "coupling": "rough.render:VirtualCoupling — K,B: the coupling's stiffness and damping",
            "device-damping": "damping — the device's own damping, as DynamicStylus' damping",
        }.items()
    },
}


def keywords(command):
    """:data:`KEYWORDS` of one command: option (without ``--``) → (keyword or callable, why)."""
    found = {}
    for key, text in KEYWORDS.items():
        name, _, option = key.rpartition("--")
        if name.strip() in ("", command):
            target, _, why = text.partition(" — ")
            found[option] = (target, why)
    return found


#: Options whose default differs from their keyword's on purpose: command → {option: why}.
DEFAULTS = {
    "render": {"realtime": "a device runs in real time (Settings); the simulation runs as fast as it can"},
    "experiment run": {"realtime": "as for render: the simulated subject answers as fast as it can"},
}

#: Options that are no keyword of the library yet: command → {option: what is missing}.
#: tests/test_api_parity.py requires each still to be missing, so that this list only
#: shrinks.
NOT_YET = {}
