% Render a Texel texture with the texel command, load the .mat it writes and
% look at it: the map, its parameters, its texels and its spectrum.
% Runs in MATLAB and in GNU Octave (no display needed):
%   octave-cli --no-gui --no-history --eval "texel = 'build/bin/texel'; run('examples/matlab/render_and_plot.m')"
% `texel` (the command's path) and `out` (a folder for the files written)
% may be set before running; by default the command is found on the PATH
% and the files go to the current folder.
if ~exist('texel', 'var'), texel = 'texel'; end
if ~exist('out', 'var'), out = '.'; end
mat = fullfile(out, 'map.mat');

% 1. The command-line tool renders; the library does all the work (docs/format.md, "MATLAB .mat").
cmd = sprintf('"%s" render --central-pitch 10 --irregularity -5 --texel-length 0.25 --seed 7 -o "%s"', texel, mat);
[status, text] = system(cmd);
if status ~= 0, error('texel render failed (%d): %s', status, text); end

% 2. One load gives the map (N×1 columns), its parameters and the texels.
m = load(mat);
a = m.amplitude;
x = m.position_mm;
p = m.params;
fprintf('%s: %d samples every %.6f mm on %s (%.2f mm)\n', mat, numel(a), p.spacing_mm, p.device, p.length_mm);
fprintf('parameters: central pitch %.1f dB, irregularity %.1f dB, texel length %.2f mm, seed %d\n', ...
        p.central_pitch_db, p.irregularity_db, p.texel_length_mm, p.seed);

% 3. Check it: amplitudes in [0, 1], positions i*spacing, one texel per 0.25 mm.
assert(numel(a) == p.samples && all(a >= 0 & a <= 1), 'amplitude out of range');
assert(max(abs(x - (0:numel(a) - 1)' * p.spacing_mm)) < 1e-9, 'positions are not i*spacing');
f = m.texels.frequency_cpm;
assert(numel(f) == floor(p.length_mm / p.texel_length_mm), 'texel count');
fprintf('amplitude: mean %.4f, min %.4f, max %.4f\n', mean(a), min(a), max(a));
% The texels' frequencies are log-normal around the central pitch (10 dB = 10 cycles/mm).
fprintf('texels: %d, median frequency %.2f cycles/mm (%.2f dB)\n', numel(f), median(f), 10 * log10(median(f)));

% 4. Its spectrum: the peak lies near the central pitch.
n = numel(a);
A = abs(fft(a - mean(a)));
k = 1:floor(n / 2);
fk = (k - 1) / (n * p.spacing_mm);   % cycles/mm
[~, i] = max(A(k));
fprintf('spectrum peak: %.2f cycles/mm\n', fk(i));

% 5. A figure, where there is a display (MATLAB, or Octave with graphics).
if usejava('awt') || (exist('OCTAVE_VERSION', 'builtin') && ~isempty(available_graphics_toolkits()) && ~isempty(getenv('DISPLAY')))
  subplot(2, 1, 1); plot(x, a); xlabel('position (mm)'); ylabel('amplitude'); title('Texel map');
  subplot(2, 1, 2); semilogx(fk(2:end), A(k(2:end))); xlabel('spatial frequency (cycles/mm)'); ylabel('|A|');
  print(fullfile(out, 'map.png'), '-dpng');
  fprintf('figure: %s\n', fullfile(out, 'map.png'));
end
