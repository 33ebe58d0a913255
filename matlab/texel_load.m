% TEXEL_LOAD  load a .mat file Texel wrote, with its text as char in MATLAB
% and in GNU Octave (docs/matlab.md, ".mat files").
%
%   m = texel_load('map.mat');        % as load('map.mat')
%   m.params.device                   % 'tpad' (char), v5 and v7.3 alike
%
% In MATLAB and for v5 files this is load(PATH). For a v7.3 file in GNU
% Octave it converts the text back to char: Texel stores text the way MATLAB
% stores char (a uint16 dataset of UTF-16 code units marked
% MATLAB_class = 'char'), and Octave's load ignores that mark and returns
% the code units as uint16. Texel writes no other uint16 variable, so every
% uint16 array of such a file is text; it becomes a char row (UTF-8, as
% Octave keeps text). An empty value is stored as its size (uint64, marked
% MATLAB_empty), which Octave returns as that uint64 pair; it becomes an
% empty char (Octave cannot tell an empty char from an empty number
% there, and Texel's empty values are text). Octave cannot read v7.3 cell arrays at all (it warns
% "can't read ... (unknown datatype)" and leaves them out): use v5, the
% default, for `texel experiment export` files in Octave.
function m = texel_load(path)
  if nargin ~= 1 || ~ischar(path)
    error('texel:invalidArgument', 'texel_load: expected the path of a .mat file');
  end
  m = load(path);
  if exist('OCTAVE_VERSION', 'builtin') && is_v73(path)
    m = text_to_char(m);
  end
end

function yes = is_v73(path)
  f = fopen(path, 'r');
  if f < 0
    error('texel:ioError', 'texel_load: cannot open %s', path);
  end
  head = fread(f, [1 19], 'uint8=>char');
  fclose(f);
  yes = strcmp(head, 'MATLAB 7.3 MAT-file');
end

function v = text_to_char(v)
  if isstruct(v)
    names = fieldnames(v);
    for k = 1:numel(v)
      for i = 1:numel(names)
        v(k).(names{i}) = text_to_char(v(k).(names{i}));
      end
    end
  elseif isa(v, 'uint16')
    units = v(:)';
    if all(units < 128)
      v = char(units);  % ASCII: one code unit, one character
    else
      v = native2unicode(typecast(units, 'uint8'), 'UTF-16LE');
    end
  elseif isa(v, 'uint64') && numel(v) == 2 && any(v == 0)
    v = char(zeros(double(v(:)')));
  end
end
