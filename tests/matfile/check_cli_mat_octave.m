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
% 'char', checked through h5py in check_cli_mat.py). Octave 7's load reads
% only HDF5 string datasets as char, so it returns the code units; the text
% is exact (docs/matlab.md). Fails when Octave starts reading MATLAB's char.
m73 = load([out '/map73.mat']);
d = m73.params.device;
assert(isa(d, 'uint16') && strcmp(char(d(:)'), 'tpad'), sprintf('v7.3 params.device: class %s', class(d)));
doc = char(m73.document(:)');
assert(strcmp(doc, m.document), 'v7.3 document is the v5 document, code unit for code unit');
assert(isequal(m73.amplitude, m.amplitude), 'v7.3 amplitude equals v5');
printf('v7.3: params.device reads as uint16 [%s] (Octave''s loader), char() gives ''%s''\n', num2str(double(d(:)')), char(d(:)'));
