% TEXEL_RENDER2D  A 2-D document's friction bitmap (docs/matlab.md), as
% `texel render DOC --surface 2d` renders it.
%
%   map = texel_render2d('surface.texel.json')                 % amplitudes 0 … 1
%   px  = texel_render2d('surface.texel.json', 'output', 'pixels')
%   s   = texel_render2d('big.texel.json', 'rows', [4096 64])   % a strip of rows
%   texel_render2d('surface.texel.json', 'file', 'map.png')     % written by libtexel
%   [map, info] = texel_render2d(...)
%
% The document is version 4 with a surface2d, on a device with a bitmap grid.
% map is height × width: map(j+1, i+1) is the pixel at x = i·pitch, y = j·pitch.
% Options:
%   output  'amplitude' (double, before polarity) ['amplitude'], 'pixels' (the
%           device's bitmap depth, uint8 or uint16, and its polarity: the PNG's
%           pixels), 'u8' or 'u16' (pixels of that depth)
%   rows    [first count]: only those rows (first is 0-based); any strip has the
%           whole map's values, so large maps render a strip at a time
%   file    write the bitmap to this file instead (.png, .npy, .mat, .gltf, .glb),
%           strip by strip and atomically; returns []
%   depth   PNG bits for 'file', 8 or 16 [0 = the device's]
% info: width_px, height_px, pixel_pitch_mm, depth_bits, polarity, first_row.
%
% This file is the help text; the MEX function built from texel_render2d.c
% (docs/matlab.md) runs instead of it.
function varargout = texel_render2d(varargin)
  error('texel:notBuilt', 'texel_render2d is not built: compile matlab/texel_render2d.c with mex or mkoctfile --mex (docs/matlab.md)');
end
