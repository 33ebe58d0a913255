"""A step-wise staircase loop, the way a PsychoPy experiment drives it.

The staircase is the engine's own state machine: next() gives the intensity to
present, answer() takes the response. Here a simulated observer answers
(threshold 0.3 mm texel length, 2AFC); in an experiment, the answer would come
from the participant after presenting `texel.render(texel_length_mm=x, ...)`.

Run after `make python`:
    PYTHONPATH=build/python /usr/bin/python3 examples/python/staircase_loop.py
"""
import texel

stair = texel.Staircase(1.0, [0.2, 0.1, 0.05], n_up=1, n_down=3, step_type="lin", min_value=0.05, max_value=2.0,
                        n_reversals=8, n_trials=20)
observer = texel.PsychometricObserver(shape="weibull", threshold=0.3, slope=3.5, guess=0.5, seed=4)

trial = 0
while not stair.finished:
    length_mm = stair.next()
    # stimulus = texel.render(texel_length_mm=length_mm, seed=trial)  # what a front end would present
    correct = observer.respond(length_mm, trial)
    stair.answer(correct)
    mark = " reversal" if stair.last_was_reversal else ""
    print(f"trial {trial:2d}: texel length {length_mm:.3f} mm -> {'correct' if correct else 'wrong'}{mark}")
    trial += 1

k = min(6, len(stair.reversal_intensities))
print(f"finished after {stair.trials} trials; threshold (mean of last {k} reversals) "
      f"{stair.mean_last_reversals(k):.3f} mm; the observer's 79.4 % point is {observer.inverse(0.794):.3f} mm")
