% TEXEL_REFERENCE  one of Texel's reference textures on a device
% (docs/matlab.md; `texel reference --list` names them).
%
%   [map, info] = texel_reference('pink', 'seed', 3, 'device', 'tpad', 'output', 'native')
%
% Options: seed [1], device ['tpad'], output ('amplitude' | 'u16' | 'native',
% as texel_render). The map equals `texel reference NAME --seed S --device D
% -o map.bin` byte for byte; info as texel_render's, with name and seed.
%
% This file is the help text; the MEX function built from texel_reference.c
% (docs/matlab.md) runs instead of it.
function varargout = texel_reference(varargin)
  error('texel:notBuilt', 'texel_reference is not built: compile matlab/texel_reference.c with mex or mkoctfile --mex (docs/matlab.md)');
end
