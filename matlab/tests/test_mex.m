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
    text = regexprep(err.message, '^texel_[a-z]+: ', '');
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
% Each function's help text (matlab/texel_*.m) names its options.
for fn = {'texel_render', 'texel_encode', 'texel_decode', 'texel_spectrum', 'texel_reference'}
  h = get_help_text([srcdir '/' fn{1} '.m']);
  assert(~isempty(strfind(h, upper(fn{1}))) && ~isempty(strfind(h, 'docs/matlab.md')), ['help text of ' fn{1}]);
end
printf('all MEX checks passed\n');
