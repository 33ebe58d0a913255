"""Running a protocol's sessions from Python: the experiment engine the
terminal runner (``texel experiment run``) and the studio drive, stepped by
your own loop — a PsychoPy window loop, a plain ``while`` — one question at
a time (examples/python/psychopy_session.py).

    import texel
    from texel.experiment import Presenter, Session

    with texel.Store("study.db", mode="rw") as store, \\
         Session(store, "examples/protocols/texel-length.json", "P01") as s, \\
         Presenter("audio") as player:
        while not s.finished:
            q = s.question                    # dict: prompt, stimuli, choices, ...
            s.present(player, 0)              # play a stimulus; switch with present(player, i)
            s.record({"choice": ask(q)})      # stored (committed) before the next question

Session(store, protocol, participant, resume=, simulate=) opens or resumes a
session; record() validates an answer and commits the trial;
simulated_response() answers for a simulated participant. Presenter plays
stimuli on a backend ('null', 'audio', 'serial:PATH'); Session.stimulus(i)
gives a stimulus as a texel.Document for output of your own.
simulate_cohort() runs simulated participants to the end. analyze() summarises
and draws a database's or export's studies as `texel experiment analyze`
does, with the library's options (analysis_options() lists them).
presentation_channels(protocol) is the Presenter's channels= for a protocol
whose device has several actuators (one output channel each).
"""

from . import _front, _texel

Presenter = _texel.experiment.Presenter
Session = _texel.experiment.Session
simulate_cohort = _texel.experiment.simulate_cohort
presentation_channels = _texel.experiment.presentation_channels
analyze = _texel.experiment.analyze
analysis_options = _texel.experiment.analysis_options

__all__ = ["Presenter", "Session", "analysis_options", "analyze", "presentation_channels", "simulate_cohort"]

globals().update(_front.apply(_texel.experiment, __name__, _front.pathlib.Path(__file__).with_suffix(".pyi"), {}))
