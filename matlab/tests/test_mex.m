% The MEX functions (matlab/*.c) against the texel command, from GNU Octave
% (tests/capi/CMakeLists.txt, test capi.mex). Set before running:
%   mexdir (the built .mex files), srcdir (matlab/: help texts), texel (the CLI),
%   out (a scratch folder).
% Each check is an assert: a failure is an error and a non-zero exit.
addpath(mexdir);

function bytes = read_bytes(path)
  f = fopen(path, 'r');
  assert(f >= 0, ['cannot read ' path]);
  bytes = fread(f, Inf, 'uint8=>uint8');
  fclose(f);
end

function text = cli(texel, args)
  [status, text] = system(sprintf('"%s" %s 2>&1', texel, args));
  assert(status == 0, sprintf('texel %s failed (%d): %s', args, status, text));
end

% The CLI's one-line error for the same mistake (exit 2, nothing on stdout).
function line = cli_error(texel, args)
  [status, text] = system(sprintf('"%s" %s 2>&1', texel, args));
  assert(status == 2, sprintf('texel %s exited %d: %s', args, status, text));
  line = strtrim(text);
end

function same_bytes(a, b, what)
  assert(isequal(size(a), size(b)) && isequal(a, b), sprintf('%s: %d bytes vs the CLI''s %d', what, numel(a), numel(b)));
  printf('%s: %d bytes, the same as the CLI\n', what, numel(a));
end

% render: the device bytes of `texel render`.
[map, info] = texel_render('central_pitch_db', 10, 'irregularity_db', -5, 'texel_length_mm', 0.25, 'seed', 7, ...
                           'device', 'tpad', 'output', 'native');
cli(texel, sprintf('render --central-pitch 10 --irregularity -5 --texel-length 0.25 --seed 7 --device tpad -o "%s/render.bin"', out));
same_bytes(map, read_bytes([out '/render.bin']), 'texel_render');
assert(strcmp(info.device, 'tpad') && strcmp(info.format, 'u16le') && info.samples == numel(map) / 2);
assert(abs(info.spacing_mm * info.samples - info.length_mm) < 1e-9 && numel(info.position_mm) == info.samples);
assert(info.params.central_pitch_db == 10 && info.params.seed == uint64(7) && strcmp(info.params.parameterization, 'moments'));
doc = jsondecode(info.document);
[u16, ~] = texel_render('central_pitch_db', 10, 'irregularity_db', -5, 'texel_length_mm', 0.25, 'seed', 7, 'output', 'u16');
assert(isa(u16, 'uint16') && isequal(typecast(u16, 'uint8'), map));
a = texel_render('central_pitch_db', 10, 'irregularity_db', -5, 'texel_length_mm', 0.25, 'seed', 7);
assert(isa(a, 'double') && isequal(uint16(round(a * 65535)), u16));
% The document it returns renders the same map.
f = fopen([out '/doc.texel.json'], 'w'); fputs(f, info.document); fclose(f);
same_bytes(texel_render('document', [out '/doc.texel.json'], 'output', 'native'), map, 'texel_render(document)');

% reference: `texel reference`.
ref = texel_reference('pink', 'seed', 3, 'output', 'native');
cli(texel, sprintf('reference pink --seed 3 --device tpad -o "%s/pink.bin"', out));
same_bytes(ref, read_bytes([out '/pink.bin']), 'texel_reference');

% encode: the same bitstream and parameters as `texel encode` of the same map,
% from the file and from the array.
json = jsondecode(cli(texel, sprintf('encode "%s/render.bin" --device tpad --json -o "%s/render.texel"', out, out)));
cli_bytes = read_bytes([out '/render.texel']);
r = texel_encode([out '/render.bin'], 'device', 'tpad');
same_bytes(r.bitstream, cli_bytes, 'texel_encode(file)');
r2 = texel_encode(double(u16) / 65535, 'spacing_mm', info.spacing_mm);
same_bytes(r2.bitstream, cli_bytes, 'texel_encode(array)');
% The same parameters as the CLI reports (its --json estimate).
e = json.estimate;
assert(r.central_pitch_db == e.central_pitch_db && r.irregularity_db == e.irregularity_db && ...
       r.texel_length_mm == e.texel_length_mm && r.seed == e.seed && strcmp(r.parameterization, e.parameterization) && ...
       r.coarse_strength == e.coarse_strength && r.fine_strength == e.fine_strength, 'texel_encode parameters differ from the CLI''s');
assert(abs(r.distance_jnd - json.model.distance_jnd) <= 1e-12 && isequal(r2.central_pitch_db, r.central_pitch_db));
printf('texel_encode: P = %.4f dB, I = %.4f dB, %.4f mm, distance %.4f JND\n', r.central_pitch_db, r.irregularity_db, ...
       r.texel_length_mm, r.distance_jnd);

% decode: `texel decode` of that bitstream, from the bytes and from the file.
cli(texel, sprintf('decode "%s/render.texel" --device tpad -o "%s/decoded.bin"', out, out));
decoded = read_bytes([out '/decoded.bin']);
same_bytes(texel_decode(r.bitstream, 'device', 'tpad', 'output', 'native'), decoded, 'texel_decode(bytes)');
same_bytes(texel_decode([out '/render.texel'], 'output', 'native'), decoded, 'texel_decode(file)');

% spectrum: `texel spectrum --json` of the same map.
s = texel_spectrum(double(u16) / 65535, 'spacing_mm', info.spacing_mm);
c = jsondecode(cli(texel, sprintf('spectrum "%s/render.bin" --device tpad --json', out)));
close_to = @(x, y) abs(x - y) <= 1e-9 * max(1, abs(y));
assert(s.samples == c.samples && s.nfft == c.nfft && close_to(s.bin_cpm * s.nfft, c.spacing_mm ^ -1));
assert(close_to(s.centroid_cpm, c.summary.centroid_cpm) && close_to(s.log_centroid_db, c.summary.log_centroid_db));
assert(close_to(s.spread_cpm, c.summary.spread_cpm) && close_to(s.rms_amplitude, c.rms_amplitude));
assert(numel(s.peaks.frequency_cpm) == numel(c.peaks));
for k = 1:numel(c.peaks)
  assert(close_to(s.peaks.frequency_cpm(k), c.peaks(k).frequency_cpm) && close_to(s.peaks.level_db(k), c.peaks(k).level_db));
end
printf('texel_spectrum: centroid %.4f cpm, %d peaks, as texel spectrum --json\n', s.centroid_cpm, numel(c.peaks));

% Errors: MATLAB errors carrying the CLI's one-line message.
function expect_error(f, id, message)
  try
    f();
  catch err
    assert(strcmp(err.identifier, id), sprintf('identifier %s, expected %s', err.identifier, id));
    % Octave puts the MEX function's name first ("texel_render: ..."); MATLAB does not.
    text = regexprep(err.message, '^texel_[a-z0-9]+: ', '');
    assert(~isempty(strfind(message, text)), sprintf('message "%s" is not in the CLI''s "%s"', text, message));
    printf('error %s: %s\n  CLI: %s\n', err.identifier, text, message);
    return;
  end
  error('no error raised');
end
expect_error(@() texel_render('texel_length_mm', 2000), 'texel:invalidArgument', ...
             cli_error(texel, sprintf('render --texel-length 2000 -o "%s/x.bin"', out)));
expect_error(@() texel_reference('no-such-reference'), 'texel:invalidArgument', ...
             cli_error(texel, sprintf('reference no-such-reference -o "%s/x.bin"', out)));
f = fopen([out '/x.texel'], 'w'); fwrite(f, uint8([1 2 3])); fclose(f);
expect_error(@() texel_decode(uint8([1 2 3])), 'texel:formatError', ...
             cli_error(texel, sprintf('decode "%s/x.texel" --device tpad -o "%s/x.bin"', out, out)));
expect_error(@() texel_render('device', 'no-such-device'), 'texel:invalidArgument', ...
             cli_error(texel, sprintf('render --device no-such-device -o "%s/x.bin"', out)));
% 2-D surfaces: texel_render2d and texel_swipe2d against `texel render --surface 2d` and `texel swipe --path/--trace-2d`.
doc2d = [srcdir '/../tests/capi/surface2d-disc.texel.json'];
[amp, info2d] = texel_render2d(doc2d);
assert(isequal(size(amp), [48 80]) && info2d.width_px == 80 && info2d.pixel_pitch_mm == 0.05 && info2d.depth_bits == 16);
cli(texel, sprintf('render "%s" --surface 2d -o "%s/s2d.mat"', doc2d, out));
m = load([out '/s2d.mat']);
assert(isequal(m.amplitude, amp), 'texel_render2d amplitudes differ from the CLI''s .mat');
printf('texel_render2d: %d x %d amplitudes, the same as the CLI\n', rows(amp), columns(amp));
assert(isequal(texel_render2d(doc2d, 'rows', [17 9]), amp(18:26, :)));
px = texel_render2d(doc2d, 'output', 'pixels');
assert(isa(px, 'uint16') && isequal(px, uint16(round(amp * 65535))));
assert(isa(texel_render2d(doc2d, 'output', 'u8'), 'uint8'));
texel_render2d(doc2d, 'file', [out '/mex.png']);
cli(texel, sprintf('render "%s" --surface 2d -o "%s/cli.png"', doc2d, out));
same_bytes(read_bytes([out '/mex.png']), read_bytes([out '/cli.png']), 'texel_render2d(file)');

% The float samples of a WAV's data chunk.
function v = wav_floats(bytes)
  pos = 13;
  while pos + 8 <= numel(bytes)
    n = double(typecast(bytes(pos + 4:pos + 7), 'uint32'));
    if isequal(char(bytes(pos:pos + 3))', 'data')
      v = typecast(bytes(pos + 8:pos + 7 + n), 'single');
      return;
    end
    pos = pos + 8 + n + mod(n, 2);
  end
  error('no data chunk');
end
cli(texel, sprintf(['swipe "%s" --path circle --radius 1 --start 2 --start-y 1.2 --speed 50 --duration 0.2 ' ...
                    '--wav-format float -o "%s/circle.wav"'], doc2d, out));
[o, x, y] = texel_swipe2d(doc2d, 'circle', 'radius_mm', 1, 'start_x_mm', 2, 'start_y_mm', 1.2, 'speed_mm_s', 50, ...
                          'duration_s', 0.2);
assert(isa(o, 'single') && numel(o) == 9600 && abs(x(1) - 3) < 1e-6 && abs(y(1) - 1.2) < 1e-6);
assert(isequal(o, wav_floats(read_bytes([out '/circle.wav']))), 'texel_swipe2d(circle) differs from texel swipe');
printf('texel_swipe2d(circle): %d samples, the same as the CLI\n', numel(o));
% A recorded trace (N×4 with touch) as `--trace-2d`.
t = (0:100)' / 1000;
trace = [1 + 40 * t, 0.5 + 20 * t, t, [ones(100, 1); 0]];
f = fopen([out '/trace.csv'], 'w'); fprintf(f, 'time_s,x_mm,y_mm,touch\n');
fprintf(f, '%.17g,%.17g,%.17g,%d\n', [trace(:, 3), trace(:, 1), trace(:, 2), trace(:, 4)]'); fclose(f);
cli(texel, sprintf('swipe "%s" --trace-2d "%s/trace.csv" --output amplitude --wav-format float -o "%s/trace.wav"', ...
                   doc2d, out, out));
o = texel_swipe2d(doc2d, trace, 'output', 'amplitude');
assert(isequal(o, wav_floats(read_bytes([out '/trace.wav']))), 'texel_swipe2d(trace) differs from texel swipe --trace-2d');
printf('texel_swipe2d(trace): %d samples, the same as the CLI\n', numel(o));
assert(~isequal(texel_swipe2d(doc2d, trace, 'output', 'amplitude', 'mode', 'bitmap'), o));

% 2-D encoding: texel_encode2d of a matrix and of the same map as a .npy file give one result; 'save' writes a
% document texel_render2d renders at the map's size.
function write_npy(path, A)  % float64, C order (rows along y)
  hdr = sprintf('{''descr'': ''<f8'', ''fortran_order'': False, ''shape'': (%d, %d), }', rows(A), columns(A));
  hdr = [hdr repmat(' ', 1, 63 - mod(10 + numel(hdr), 64)) char(10)];
  f = fopen(path, 'w');
  fwrite(f, [147 double('NUMPY') 1 0], 'uint8'); fwrite(f, numel(hdr), 'uint16'); fwrite(f, hdr, 'char');
  fwrite(f, A', 'double'); fclose(f);
end
[X, Y] = meshgrid((0:399) * 0.05, (0:399) * 0.05);
A = 0.5 + 0.25 * sin(2 * pi * (2 * X + Y)) + 0.25 * sin(2 * pi * (-1.5 * X + 2.5 * Y));
write_npy([out '/map2d.npy'], A);
cheap = {'directions', 4, 'scan_samples', 1024, 'correction_rounds', 0};
e1 = texel_encode2d(A, 'pitch_mm', 0.05, cheap{:});
e2 = texel_encode2d([out '/map2d.npy'], 'pitch_mm', 0.05, cheap{:}, 'save', [out '/map2d.texel.json']);
assert(strcmp(e2.document, [out '/map2d.texel.json']));
assert(isequal(e1, rmfield(e2, 'document')), 'texel_encode2d of the .npy differs from the matrix''s');
assert(strcmp(e1.method, 'bitmap') && numel(e1.anisotropy.directions) == 4 && isfinite(e1.estimate.central_pitch_db));
[amp2, info2] = texel_render2d([out '/map2d.texel.json']);
assert(info2.width_px == 400 && info2.height_px == 400 && info2.pixel_pitch_mm == 0.05);
printf('texel_encode2d: P %.2f dB, I %.2f dB, the matrix and the .npy alike\n', e1.estimate.central_pitch_db, ...
       e1.estimate.irregularity_db);
expect_error(@() texel_encode2d(A), 'texel:invalidArgument', 'a matrix needs ''pitch_mm'' (the distance between its pixels, mm)');
expect_error(@() texel_encode2d([out '/map2d.npy'], cheap{:}), 'texel:invalidArgument', ...
             cli_error(texel, sprintf('encode "%s/map2d.npy" --directions 4', out)));

% encode target: a map whose felt pitch and log-spectral centroid differ.
xs = (0:8191)' * 0.01;
g = sin(2 * pi * 2 * xs) + 0.5 * sin(2 * pi * 4 * xs + 1) + 0.25 * sin(2 * pi * 6 * xs + 2);
for k = 0:39
  g = g + 0.05 * sin(2 * pi * (6 + 0.3 * k) * xs + k);
end
g = (g - min(g)) / (max(g) - min(g));
felt = texel_encode(g, 'spacing_mm', 0.01);
centroid = texel_encode(g, 'spacing_mm', 0.01, 'target', 'centroid');
assert(strcmp(felt.target, 'felt') && strcmp(centroid.target, 'centroid'));
assert(centroid.central_pitch_db > felt.central_pitch_db + 1, 'the centroid target moves Central Pitch');
printf('texel_encode target: felt %.2f dB, centroid %.2f dB\n', felt.central_pitch_db, centroid.central_pitch_db);
expect_error(@() texel_encode(g, 'spacing_mm', 0.01, 'target', 'loudest'), 'texel:invalidArgument', ...
             'target ''loudest'' is not one of automatic, felt, centroid');

expect_error(@() texel_render2d([out '/doc.texel.json']), 'texel:invalidArgument', ...
             cli_error(texel, sprintf('render "%s/doc.texel.json" --surface 2d -o "%s/x.png"', out, out)));
expect_error(@() texel_swipe2d(doc2d, 'spiral'), 'texel:invalidArgument', ...
             'path ''spiral'' is not one of line, circle, zigzag');
expect_error(@() texel_swipe2d(doc2d, [0 0 1; 0 0 0.5]), 'texel:invalidArgument', ...
             'trace[1].t_s is below the sample before; times must be non-decreasing');

% One input, one answer (docs/c-api.md "Input amplitudes"): a map outside [0, 1]
% is scaled to full range by the library's rule, as `texel encode` reads the
% same array from a .npy file — never clamped; a constant one is refused by both.
function write_npy1(path, v)  % float64, shape (N,)
  hdr = sprintf('{''descr'': ''<f8'', ''fortran_order'': False, ''shape'': (%d,), }', numel(v));
  hdr = [hdr repmat(' ', 1, 63 - mod(10 + numel(hdr), 64)) char(10)];
  f = fopen(path, 'w');
  fwrite(f, [147 double('NUMPY') 1 0], 'uint8'); fwrite(f, numel(hdr), 'uint16'); fwrite(f, hdr, 'char');
  fwrite(f, v(:), 'double'); fclose(f);
end
write_npy1([out '/times100.npy'], a * 100);
cli(texel, sprintf('encode "%s/times100.npy" --spacing %.17g -o "%s/times100.texel"', out, info.spacing_mm, out));
r100 = texel_encode(a * 100, 'spacing_mm', info.spacing_mm);
same_bytes(r100.bitstream, read_bytes([out '/times100.texel']), 'texel_encode(map x 100)');
same_bytes(texel_encode(u16, 'spacing_mm', info.spacing_mm).bitstream, r2.bitstream, 'texel_encode(uint16 map)');
write_npy1([out '/constant.npy'], 2 * ones(1000, 1));
refusal = cli_error(texel, sprintf('encode "%s/constant.npy" --spacing 0.01', out));
try
  texel_encode(2 * ones(1000, 1), 'spacing_mm', 0.01);
  error('texel_encode accepted a constant map outside [0, 1]');
catch err
  assert(strcmp(err.identifier, 'texel:invalidArgument') && ~isempty(strfind(err.message, 'constant: it holds no texture')) ...
         && ~isempty(strfind(refusal, 'constant: it holds no texture')), err.message);
  printf('constant map outside [0, 1] refused: %s\n  CLI: %s\n', err.message, refusal);
end
% A 'native' map's uint8 bytes are not amplitudes.
expect_error(@() texel_spectrum(map, 'spacing_mm', info.spacing_mm), 'texel:invalidArgument', ...
             ['the map is uint8, which Texel reads as device bytes (texel_render''s ''native'' output), not amplitudes; ' ...
              'give amplitudes as double in [0, 1] (texel_render''s default output) or uint16 (its ''u16'' output)']);
expect_error(@() texel_encode(map, 'spacing_mm', info.spacing_mm), 'texel:invalidArgument', ...
             ['the map is uint8, which Texel reads as device bytes (texel_render''s ''native'' output), not amplitudes; ' ...
              'give amplitudes as double in [0, 1] (texel_render''s default output) or uint16 (its ''u16'' output)']);
expect_error(@() texel_spectrum(int32(u16), 'spacing_mm', info.spacing_mm), 'texel:invalidArgument', ...
             'the map is int32; allowed: double or single amplitudes, uint16 (/65535) or int16 (/32768)');

% Each function's help text (matlab/texel_*.m) names its options.
for fn = {'texel_render', 'texel_encode', 'texel_decode', 'texel_spectrum', 'texel_reference', 'texel_render2d', 'texel_swipe2d'}
  h = get_help_text([srcdir '/' fn{1} '.m']);
  assert(~isempty(strfind(h, upper(fn{1}))) && ~isempty(strfind(h, 'docs/matlab.md')), ['help text of ' fn{1}]);
end
printf('all MEX checks passed\n');
