% What `texel render -o map.mat` writes, loaded by GNU Octave's `load`
% (tests/matfile/CMakeLists.txt). Set `texel` (the CLI) and `out` (a
% scratch folder) before running.
args = '--central-pitch 10 --irregularity -5 --texel-length 0.25 --seed 7 --device tpad';
[st, txt] = system(sprintf('"%s" render %s -o "%s/map.mat"', texel, args, out));
assert(st == 0, txt);
[st, txt] = system(sprintf('"%s" render %s -o "%s/map73.mat" --mat-version 7.3', texel, args, out));
assert(st == 0, txt);

% v5: text is char.
m = load([out '/map.mat']);
assert(ischar(m.params.device) && strcmp(m.params.device, 'tpad'), 'v5 params.device is char ''tpad''');
assert(ischar(m.document) && ~isempty(strfind(m.document, '"device"')), 'v5 document is char JSON');
printf('v5: params.device is char ''%s'', document %d characters\n', m.params.device, numel(m.document));

% v7.3: Texel writes text as MATLAB does (uint16 UTF-16 with MATLAB_class
% 'char', checked through h5py in check_cli_mat.py). Octave's load ignores
% MATLAB_class and reads every integer dataset as an integer array (its
% ls-hdf5.cc; a file with MATLAB's exact char layout reads the same), so
% plain load returns the code units; the text is exact (docs/matlab.md).
% Fails when Octave starts reading MATLAB's char, so the docs get updated.
m73 = load([out '/map73.mat']);
d = m73.params.device;
assert(isa(d, 'uint16') && strcmp(char(d(:)'), 'tpad'), sprintf('v7.3 params.device: class %s', class(d)));
doc = char(m73.document(:)');
assert(strcmp(doc, m.document), 'v7.3 document is the v5 document, code unit for code unit');
assert(isequal(m73.amplitude, m.amplitude), 'v7.3 amplitude equals v5');
printf('v7.3: plain load reads params.device as uint16 [%s] (Octave''s loader)\n', num2str(double(d(:)')));

% texel_load (matlab/texel_load.m) gives the text as char: the v7.3 file
% loads equal to the v5 one, variable for variable, non-ASCII text included
% (a description with a two-byte and a four-byte UTF-8 character, the last
% a UTF-16 surrogate pair in the file).
addpath(srcdir);
t73 = texel_load([out '/map73.mat']);
assert(ischar(t73.params.device) && strcmp(t73.params.device, 'tpad'), 'texel_load v7.3 params.device is char ''tpad''');
assert(ischar(t73.document) && isequal(t73, m), 'texel_load of the v7.3 file equals load of the v5 file');
assert(isequal(texel_load([out '/map.mat']), m), 'texel_load of a v5 file is load');
doc = jsondecode(m.document);
doc.description = ['ridges 2 ' char([194 181]) 'm ' char([240 159 152 128])];
f = fopen([out '/u.texel.json'], 'w'); fwrite(f, jsonencode(doc)); fclose(f);
for v = {'5', '7.3'}
  [st, txt] = system(sprintf('"%s" render "%s/u.texel.json" -o "%s/u%s.mat" --mat-version %s', texel, out, out, v{1}, v{1}));
  assert(st == 0, txt);
end
u5 = load([out '/u5.mat']);
u73 = texel_load([out '/u7.3.mat']);
assert(strcmp(u5.params.description, doc.description) && isequal(u73, u5), 'texel_load: non-ASCII v7.3 text equals v5');
printf('v7.3 through texel_load: params.device is char ''%s'', description ''%s''\n', t73.params.device, u73.params.description);
