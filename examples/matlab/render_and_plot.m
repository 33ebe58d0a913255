% Render a Texel texture from MATLAB or GNU Octave through the MEX functions
% (docs/matlab.md), look at it, analyse it and encode it back.
% Runs without a display:
%   octave-cli --no-gui --eval "mexdir = 'build/matlab'; run('examples/matlab/render_and_plot.m')"
% `mexdir` (where texel_render.mex etc. are) and `out` (a folder for the
% figure) may be set before running; by default the functions are found on
% the path and the figure goes to the current folder.
if exist('mexdir', 'var'), addpath(mexdir); end
if ~exist('out', 'var'), out = '.'; end

% 1. The map: one call, the library does all the work.
[a, info] = texel_render('central_pitch_db', 10, 'irregularity_db', -5, 'texel_length_mm', 0.25, 'seed', 7, ...
                         'device', 'tpad');
x = info.position_mm;
p = info.params;
fprintf('%d samples every %.6f mm on %s (%.2f mm)\n', numel(a), info.spacing_mm, info.device, info.length_mm);
fprintf('parameters: central pitch %.1f dB, irregularity %.1f dB, texel length %.2f mm, seed %d\n', ...
        p.central_pitch_db, p.irregularity_db, p.texel_length_mm, p.seed);

% 2. Check it: amplitudes in [0, 1], positions i*spacing.
assert(numel(a) == info.samples && all(a >= 0 & a <= 1), 'amplitude out of range');
assert(max(abs(x - (0:numel(a) - 1)' * info.spacing_mm)) < 1e-9, 'positions are not i*spacing');
fprintf('amplitude: mean %.4f, min %.4f, max %.4f\n', mean(a), min(a), max(a));

% 3. Its spectrum, as `texel spectrum` reports it: the peaks lie near the
%    central pitch (10 dB = 10 cycles/mm).
s = texel_spectrum(a, 'spacing_mm', info.spacing_mm);
fprintf('spectral centroid %.2f cycles/mm (%.2f dB), %d peaks\n', s.centroid_cpm, s.log_centroid_db, numel(s.peaks.frequency_cpm));
assert(abs(s.log_centroid_db - 10) < 2, 'the spectrum is not centred near the central pitch');

% 4. Encode the map back: a bitstream of a few bytes and its parameters.
r = texel_encode(a, 'spacing_mm', info.spacing_mm);
fprintf('encoded: %d bytes, P = %.2f dB, I = %.2f dB, distance %.3f JND\n', numel(r.bitstream), r.central_pitch_db, ...
        r.irregularity_db, r.distance_jnd);
assert(abs(r.central_pitch_db - 10) < 1 && r.distance_jnd < 1, 'the encoder did not recover the texture');
b = texel_decode(r.bitstream, 'device', 'tpad');
assert(numel(b) == numel(a));

% 5. A figure, where there is a display (MATLAB, or Octave with graphics).
if usejava('awt') || (exist('OCTAVE_VERSION', 'builtin') && ~isempty(available_graphics_toolkits()) && ~isempty(getenv('DISPLAY')))
  subplot(2, 1, 1); plot(x, a); xlabel('position (mm)'); ylabel('amplitude'); title('Texel map');
  subplot(2, 1, 2); semilogx(s.frequency_cpm(2:end), s.magnitude(2:end)); xlabel('spatial frequency (cycles/mm)'); ylabel('|A|');
  print(fullfile(out, 'map.png'), '-dpng');
  fprintf('figure: %s\n', fullfile(out, 'map.png'));
end
