% TEXEL_ENCODE2D  Texel parameters and a version-4 2-D document for a friction
% bitmap, a height map or a bundle of 1-D scans (docs/matlab.md), as
% `texel encode map.png --pitch MM`.
%
%   r = texel_encode2d(A, 'pitch_mm', 0.05)          % a height × width matrix, values in [0, 1]
%   r = texel_encode2d('map.png', 'device', 'tablet-2d', 'save', 'map.texel.json')
%   r = texel_encode2d('scans.scans.json')           % a bundle of 1-D scans along several directions
%
% The first argument is a real double matrix (rows along y, columns along x,
% as imread gives an image: double(imread(f)) / 65535 for a 16-bit PNG) or a
% path to a grey 8/16-bit .png, a 2-D .npy (a height map, values outside
% [0, 1], is scaled) or a .scans.json bundle.
% Options (defaults as `texel encode`):
%   pitch_mm          the pixel pitch, mm (required for a matrix; for a file,
%                     unless a device with a bitmap gives it)
%   device            a built-in profile name or a profile's path (files only):
%                     its bitmap's pitch and polarity, its frequency response
%   polarity          'darker_more_friction' or 'brighter_more_friction': how a
%                     PNG's levels read [the device's, else darker]
%   swipe_speed_mm_s  for recorded scans in a bundle
%   save              a .texel.json path: writes the document and its coarse
%                     image (coarse.npy) beside it, atomically
%   directions [18], scan_samples [16384], correction_rounds [1]   the 2-D encoder
%   boundary_mm [1], texel_length_mm [0.25], parameterization ['moments'],
%   seed [1], target ['automatic'; 'felt', 'centroid']              the 1-D encoder
% r: the library's result (as `texel encode --json`): r.estimate
% (central_pitch_db, irregularity_db, texel_length_mm, parameterization, seed,
% coarse_strength, fine_strength, field, coarse), r.flags, r.anisotropy (per
% direction rows, spreads, strongest_direction_deg), r.model, r.method; with
% 'save', r.document is the path written.
%
% This file is the help text; the MEX function built from texel_encode2d.c
% (docs/matlab.md) runs instead of it.
function varargout = texel_encode2d(varargin)
  error('texel:notBuilt', 'texel_encode2d is not built: compile matlab/texel_encode2d.c with mex or mkoctfile --mex (docs/matlab.md)');
end
