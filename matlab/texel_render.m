% TEXEL_RENDER  a Texel texture's map on a device (docs/matlab.md).
%
%   [map, info] = texel_render('central_pitch_db', 10, 'irregularity_db', -5, ...
%                              'texel_length_mm', 0.25, 'seed', 7, 'device', 'tpad')
%   [map, info] = texel_render('document', 'brick.texel.json')
%
% Options (texel.h's texel_params; defaults as `texel render`):
%   device                 name or profile path ['tpad']
%   central_pitch_db       dB re 1 cycle/mm [10]     irregularity_db   dB [-5]
%   texel_length_mm        mm [0.25]                 seed              [1]
%   parameterization       'moments' | 'log'         quantization_db   0 … 20 [0]
%   coarse_strength        0 … 1 [0]                 fine_strength     0 … 1 [1]
%   coarse_sine_period_mm  0 = constant [0]          coarse_sine_phase_deg [0]
%   document               a *.texel.json path (instead of the parameters)
%   output                 'amplitude' (double in [0, 1], default) | 'u16'
%                          (uint16, round(a·65535)) | 'native' (uint8: the
%                          device's bytes, exactly `texel render -o map.bin`)
% map is a column; info holds device, samples, spacing_mm, length_mm,
% refresh_hz, format, bytes_per_sample, position_mm, params and document
% (the JSON text).
%
% This file is the help text; the MEX function built from texel_render.c
% (docs/matlab.md) runs instead of it.
function varargout = texel_render(varargin)
  error('texel:notBuilt', 'texel_render is not built: compile matlab/texel_render.c with mex or mkoctfile --mex (docs/matlab.md)');
end
