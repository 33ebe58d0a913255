% TEXEL_SWIPE2D  What a finger feels on a 2-D surface under a 2-D stroke, through
% the 2-D player (docs/matlab.md), as `texel swipe DOC --path …` / `--trace-2d`.
%
%   out = texel_swipe2d('surface.texel.json', 'circle', 'radius_mm', 10, 'start_x_mm', 20, 'start_y_mm', 20)
%   out = texel_swipe2d('surface.texel.json', 'line', 'angle_deg', 37, 'speed_mm_s', 150)
%   [out, x_mm, y_mm] = texel_swipe2d('surface.texel.json', [x y t])   % a recorded finger, N×3
%
% The second argument is a simulated path ('line', 'circle' or 'zigzag') or a
% trace: an N×3 matrix of x_mm, y_mm, t_s (times non-decreasing) or N×4 with
% touch (non-zero = on the surface) as the fourth column.
% Options (defaults as `texel swipe`):
%   speed_mm_s [100], angle_deg [0], start_x_mm [0], start_y_mm [0] (circle: its
%   centre), radius_mm [20], leg_mm [10], zigzag_deg [90]    the simulated path
%   duration_s    output length, s [2 for a path; a trace's last time]
%   rate_hz [48000], output ['vibration'; 'amplitude', 'carrier'], gain [1], carrier_hz [250]
%   mode          'path' (path-indexed: the texture along the finger's path, the
%                 coarse profile at (x, y); a surface of one region) or 'bitmap'
%                 (the document's friction bitmap at (x, y)) ['path']
%   path_at_lift  'keep' (the path continues across lifts) or 'reset' ['keep']
% out, x_mm, y_mm: single columns, one value per output sample.
%
% This file is the help text; the MEX function built from texel_swipe2d.c
% (docs/matlab.md) runs instead of it.
function varargout = texel_swipe2d(varargin)
  error('texel:notBuilt', 'texel_swipe2d is not built: compile matlab/texel_swipe2d.c with mex or mkoctfile --mex (docs/matlab.md)');
end
