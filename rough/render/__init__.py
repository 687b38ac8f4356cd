"""Haptic rendering: feel a surface profile through a force-feedback joystick.

A virtual stylus rides the profile, or a point moves over the map (:mod:`.track`); a
contact model (:mod:`.contact`) and optionally a friction model (:mod:`.friction`)
give the force on the hand; the servo loop (:mod:`.loop`) reads a device, computes and
writes that force once per period. Devices (:mod:`.device`: one interface, and the
registry of backends that :func:`backends` lists and :func:`open_device` opens by
name): the simulated hand (``sim``, :mod:`.hand`, for headless runs and tests), a HID
PID joystick through hidraw (``hid``, :mod:`.hid`), any Linux force-feedback device
through evdev (``evdev``, :mod:`.evdev`), and a plugin's, through the entry-point
group ``rough.devices``. SI units throughout: m, s, N, kg.

>>> import rough
>>> from rough.render import Track, forces, simulate
>>> track = Track.from_surface(rough.read(rough.sample("rock-profile.tsv")))
>>> result = simulate(track, speed=0.06)  # 60 mm/s, the simulated hand
>>> f"F_y {forces(result)['F_y_mean']:.3f} ± {forces(result)['F_y_std']:.3f} N"
'F_y 0.997 ± 0.347 N'
"""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
