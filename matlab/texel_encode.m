% TEXEL_ENCODE  Texel parameters and a .texel bitstream for a map or a
% recording (docs/matlab.md).
%
%   r = texel_encode(amplitude, 'spacing_mm', 0.005)      % a map in memory
%   r = texel_encode('scan.mat')                          % any file `texel encode` reads
%   r = texel_encode('map.bin', 'device', 'tpad')
%
% An array is read as `texel encode` reads the same array from a .npy file
% (docs/c-api.md "Input amplitudes"): double or single as they are, uint16
% /65535, int16 /32768; a map with any value outside [0, 1] is scaled to full
% range (0.5 + 0.5*y/max|y| of the zero-mean map), never clamped; uint8
% (texel_render's 'native' bytes) is refused.
%
% Options (texel.h's texel_encode_options; defaults as `texel encode`):
%   spacing_mm        sample spacing of an array input, mm (required for arrays)
%   device            a file's device (needed for .bin; its response joins the model)
%   swipe_speed_mm_s  finger speed: time recordings to position, and the model's speed
%   boundary_mm [1], texel_length_mm [0.25], parameterization ['moments'],
%   seed [1], coarse_bits [6], max_bytes [0 = none], recover_texel [true]
%   target            what Central Pitch matches: 'felt' (the model's felt pitch),
%                     'centroid' (the input's log-spectral centroid) or 'automatic'
%                     (centroid for time recordings, felt for maps) ['automatic']
% r holds the decoded parameters (central_pitch_db, irregularity_db, ...,
% as texel_render takes them), has_coarse_profile, distance_jnd, target
% ('felt' or 'centroid': what the fit matched) and
% bitstream (uint8 column: the .texel file `texel encode -o` writes).
%
% This file is the help text; the MEX function built from texel_encode.c
% (docs/matlab.md) runs instead of it.
function varargout = texel_encode(varargin)
  error('texel:notBuilt', 'texel_encode is not built: compile matlab/texel_encode.c with mex or mkoctfile --mex (docs/matlab.md)');
end
