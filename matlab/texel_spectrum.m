% TEXEL_SPECTRUM  what `texel spectrum` reports for a map (docs/matlab.md).
%
%   s = texel_spectrum(amplitude, 'spacing_mm', info.spacing_mm)
%   semilogx(s.frequency_cpm, s.magnitude)
%
% The map: double or single amplitudes as they are, uint16 /65535 (texel_render's
% 'u16'), int16 /32768; uint8 (texel_render's 'native' device bytes) is refused.
%
% Options (texel.h's texel_spectrum_options; defaults as the CLI's):
%   spacing_mm (required), window ('blackman-harris' | 'hann' | 'flat-top' |
%   'rectangular'), zero_pad [4], threshold_db [-40], max_peaks [32],
%   welch_segment [0 = auto], welch_overlap [0.5]
% s holds frequency_cpm and magnitude (columns), psd_frequency_cpm and psd,
% peaks (frequency_cpm, amplitude, level_db columns), bands (lo_cpm, hi_cpm,
% mean_square, fraction) and the scalars samples, spacing_mm, nfft, bin_cpm,
% resolution_cpm, mean_amplitude, rms_amplitude, centroid_cpm,
% log_centroid_db, spread_cpm, log_spread_db, welch_segment, welch_segments,
% psd_bin_cpm.
%
% This file is the help text; the MEX function built from texel_spectrum.c
% (docs/matlab.md) runs instead of it.
function varargout = texel_spectrum(varargin)
  error('texel:notBuilt', 'texel_spectrum is not built: compile matlab/texel_spectrum.c with mex or mkoctfile --mex (docs/matlab.md)');
end
