% TEXEL_DECODE  the map a .texel bitstream stands for on a device
% (docs/matlab.md).
%
%   [map, info] = texel_decode(bitstream, 'device', 'tpad')   % uint8 bytes
%   [map, info] = texel_decode('rough.texel', 'output', 'native')
%
% The first argument is the bitstream (a uint8 vector, e.g. texel_encode's
% result.bitstream) or the path of a .texel file. Options: device ['tpad'],
% output ('amplitude' | 'u16' | 'native', as texel_render). The map equals
% `texel decode FILE --device D -o map.bin` byte for byte.
%
% This file is the help text; the MEX function built from texel_decode.c
% (docs/matlab.md) runs instead of it.
function varargout = texel_decode(varargin)
  error('texel:notBuilt', 'texel_decode is not built: compile matlab/texel_decode.c with mex or mkoctfile --mex (docs/matlab.md)');
end
