"""Offline output for the command line, one module a job:

- :mod:`.render` — ``treeanim render``: videos, PNG frames and stills (:func:`.render.run_render`);
- :mod:`.trace` — ``treeanim trace``: pull-and-release tip traces, CSV and plots;
- :mod:`.bench` — ``treeanim bench``: the paper's Table 1 on this machine;
- :mod:`.sinks` — where frames go, one entry per file suffix (:data:`.sinks.VIDEO_FORMATS`);
- :mod:`.target` — checks of ``--out`` and ``--size`` before anything is simulated.

Everything renders through :class:`treeanim.render.offscreen.OffscreenRenderer` (EGL, Mesa
llvmpipe where there is no GPU) and writes through imageio / imageio-ffmpeg.

Files are written safely (:mod:`treeanim.files`): a video goes to a hidden temporary file
beside the target and is renamed over it once finished (or once interrupted, if at least one
frame was encoded), and every PNG, CSV, plot and JSON file is written beside its name and
renamed, so an interrupted or failed run leaves either nothing or a complete, playable file.
"""
