"""numba kernels of the indicators (:mod:`prsm_health.signals.kernels`): each a loop that numpy
or scipy ran as several passes over arrays larger than the cache, or in Python, now one
compiled pass. The FFTs stay numpy's."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def windowed_frames(x, start, step, window, detrend, out):
    """out[j] = window · (x[start + j·step :][: len(window)], zero outside x), each frame's
    mean removed first when ``detrend`` (Welch's segments, all inside x; the kurtogram's
    frames, zero-padded at the ends, are not detrended)."""
    n = x.shape[0]
    m = window.shape[0]
    for j in range(out.shape[0]):
        s = start + j * step
        mean = 0.0
        if detrend:
            # four partial sums: four additions in flight instead of one chain
            s0 = s1 = s2 = s3 = 0.0
            i = s
            while i + 4 <= s + m:
                s0 += x[i]
                s1 += x[i + 1]
                s2 += x[i + 2]
                s3 += x[i + 3]
                i += 4
            while i < s + m:
                s0 += x[i]
                i += 1
            mean = ((s0 + s1) + (s2 + s3)) / m
        if s >= 0 and s + m <= n:
            for i in range(m):
                out[j, i] = (x[s + i] - mean) * window[i]
        else:
            for i in range(m):
                k = s + i
                out[j, i] = (x[k] - mean) * window[i] if 0 <= k < n else 0.0


@njit(cache=True)
def add_power_sums(z, s2, s4, fourth):
    """s2 += Σ_frames |z|², and s4 += Σ_frames |z|⁴ when ``fourth``, frame after frame (the
    order of numpy's mean over the first axis)."""
    for j in range(z.shape[0]):
        for k in range(z.shape[1]):
            re = z[j, k].real
            im = z[j, k].imag
            p = re * re + im * im
            s2[k] += p
            if fourth:
                s4[k] += p * p


@njit(cache=True)
def sosfiltfilt_rows(x, sos, zi, edge, out):
    """``scipy.signal.sosfiltfilt(sos[r], x[r])`` of every row r into ``out``: odd extension
    of ``edge[r]`` samples, steady-state initial conditions ``zi[r]`` scaled by the first
    sample of each pass, scipy's transposed direct form II with the same operations in the
    same order (equal bitwise). ``sos`` (rows, 4·k, 6): the sections four at a time, a pass
    over the samples each, with their states in registers (scipy keeps them in memory); a
    cascade's output does not depend on which section runs first for a sample, so this is the
    same arithmetic. Pad with identity sections ([1, 0, 0, 1, 0, 0], zi 0) to a multiple of 4."""
    rows, n = x.shape
    buffer = np.empty(n + 2 * edge.max())
    for r in range(rows):
        e = edge[r]
        m = n + 2 * e
        y = buffer[:m]
        for i in range(e):
            y[i] = 2.0 * x[r, 0] - x[r, e - i]
        y[e : e + n] = x[r]
        for i in range(e):
            y[e + n + i] = 2.0 * x[r, n - 1] - x[r, n - 2 - i]
        first = y[0]
        for g in range(0, sos.shape[1], 4):
            _four_sections(y, sos[r, g : g + 4], zi[r, g : g + 4], first, 1)
        last = y[m - 1]
        for g in range(0, sos.shape[1], 4):
            _four_sections(y, sos[r, g : g + 4], zi[r, g : g + 4], last, -1)
        out[r] = y[e : e + n]


@njit(cache=True)
def _four_sections(y, c, zi, scale, direction):
    """Four biquads in cascade over ``y`` in place, forwards (1) or backwards (-1), their
    states starting at zi · scale."""
    a0, a1 = zi[0, 0] * scale, zi[0, 1] * scale
    b0, b1 = zi[1, 0] * scale, zi[1, 1] * scale
    c0, c1 = zi[2, 0] * scale, zi[2, 1] * scale
    d0, d1 = zi[3, 0] * scale, zi[3, 1] * scale
    m = y.shape[0]
    for k in range(m):
        i = k if direction > 0 else m - 1 - k
        v = y[i]
        u = c[0, 0] * v + a0
        a0 = c[0, 1] * v - c[0, 4] * u + a1
        a1 = c[0, 2] * v - c[0, 5] * u
        v = u
        u = c[1, 0] * v + b0
        b0 = c[1, 1] * v - c[1, 4] * u + b1
        b1 = c[1, 2] * v - c[1, 5] * u
        v = u
        u = c[2, 0] * v + c0
        c0 = c[2, 1] * v - c[2, 4] * u + c1
        c1 = c[2, 2] * v - c[2, 5] * u
        v = u
        u = c[3, 0] * v + d0
        d0 = c[3, 1] * v - c[3, 4] * u + d1
        d1 = c[3, 2] * v - c[3, 5] * u
        y[i] = u


@njit(cache=True)
def moment_sums(x, out):
    """out[r] = (Σx², Σx³, Σx⁴, max x, min x) of each row of ``x`` in one pass, the sums
    in blocks of 128 samples added block by block (the rounding of 128 + n/128 additions in
    a row, not of n)."""
    for r in range(x.shape[0]):
        s2 = s3 = s4 = 0.0
        high = -np.inf
        low = np.inf
        n = x.shape[1]
        for start in range(0, n, 128):
            b2 = b3 = b4 = 0.0
            for i in range(start, min(start + 128, n)):
                v = x[r, i]
                v2 = v * v
                b2 += v2
                b3 += v2 * v
                b4 += v2 * v2
                high = max(high, v)
                low = min(low, v)
            s2 += b2
            s3 += b3
            s4 += b4
        out[r, 0] = s2
        out[r, 1] = s3
        out[r, 2] = s4
        out[r, 3] = high
        out[r, 4] = low


@njit(cache=True)
def _chebyshev_block(position, start, count, lo, hi, degree, out):
    """out[k, i] = T_k(u) of position[start + i] mapped onto u ∈ [-1, 1], k ≤ degree: numpy's
    chebvander recurrence T_k = 2u·T_(k−1) − T_(k−2)."""
    for i in range(count):
        u = (2.0 * position[start + i] - lo - hi) / (hi - lo)
        two_u = u + u
        before, last = 1.0, u  # T_(k−2), T_(k−1) in registers, not reloaded from out
        out[0, i] = before
        if degree > 0:
            out[1, i] = last
        for k in range(2, degree + 1):
            before, last = last, last * two_u - before
            out[k, i] = last


@njit(cache=True)
def step_polynomial_normal_equations(position, side, residual, lo, hi, degree, gram, rhs):
    """The normal equations of residual ≈ Σ_k c_k·T_k(u(position)) + c_s·side (Chebyshev
    polynomials of the position mapped onto [-1, 1], and a step): gram (degree + 2)² and rhs,
    summed over blocks of 256 samples by BLAS products (no basis matrix of the whole
    window: building it was most of the fit's time)."""
    m = degree + 2
    block = np.zeros((m, 256))
    values = np.zeros(256)
    gram[:] = 0.0
    rhs[:] = 0.0
    n = position.shape[0]
    for start in range(0, n, 256):
        count = min(256, n - start)
        _chebyshev_block(position, start, count, lo, hi, degree, block)
        block[m - 1, :count] = side[start : start + count]
        values[:count] = residual[start : start + count]
        if count < 256:  # zeros past the end add nothing
            block[:, count:] = 0.0
            values[count:] = 0.0
        gram += block @ block.T
        rhs += block @ values


@njit(cache=True)
def subtract_polynomial(position, residual, lo, hi, coef, out):
    """out = residual − Σ_k coef[k]·T_k(u(position)), the polynomial of
    :func:`step_polynomial_normal_equations` (its step not subtracted); degree ≥ 1."""
    for i in range(position.shape[0]):
        u = (2.0 * position[i] - lo - hi) / (hi - lo)
        two_u = u + u
        before, last = 1.0, u
        fit = coef[0] + coef[1] * u
        for k in range(2, coef.shape[0]):
            before, last = last, last * two_u - before
            fit += coef[k] * last
        out[i] = residual[i] - fit


@njit(cache=True)
def interp_rows(x, xp, fp, out):
    """out[r] = np.interp(x, xp, fp[r]) for every row of ``fp``, ``x`` and ``xp`` increasing
    and finite: one walk along both (numpy searches xp for every x, once per row), each value
    by numpy's formula — slope·(x − xp[j]) + fp[j], fp[j] where x equals xp[j], the end
    values outside."""
    n = xp.shape[0]
    j = 0
    for i in range(x.shape[0]):
        v = x[i]
        if v < xp[0]:
            for r in range(fp.shape[0]):
                out[r, i] = fp[r, 0]
            continue
        if v >= xp[n - 1]:
            for r in range(fp.shape[0]):
                out[r, i] = fp[r, n - 1]
            continue
        while xp[j + 1] <= v:
            j += 1
        while xp[j] > v:
            j -= 1
        if xp[j] == v:
            for r in range(fp.shape[0]):
                out[r, i] = fp[r, j]
        else:
            for r in range(fp.shape[0]):
                slope = (fp[r, j + 1] - fp[r, j]) / (xp[j + 1] - xp[j])
                out[r, i] = slope * (v - xp[j]) + fp[r, j]


@njit(cache=True)
def hysteresis_crossings(x, lower, upper):
    """Times ``x`` passes from above ``upper`` to below ``lower`` or back (samples in
    between keep the last side)."""
    side = 0
    count = 0
    for v in x:
        now = 1 if v > upper else -1 if v < lower else 0
        if now != 0:
            if side != 0 and now != side:
                count += 1
            side = now
    return count


@njit(cache=True)
def screw_power_sums(torque, speed, load, position, time):
    """(Σ|F·v|, Σ(T·ω − F·v)): the power through the screw and the loss, v the nut speed by
    numpy.gradient(position, time) (second-order central differences, first-order at the
    ends: its formulas for an uneven grid, in its order, which an even one reduces to), the
    sums in blocks of 128 samples added block by block (as :func:`moment_sums`)."""
    n = position.shape[0]
    through = loss = 0.0
    block_through = block_loss = 0.0
    for i in range(n):
        if i == 0:
            v = (position[1] - position[0]) / (time[1] - time[0])
        elif i == n - 1:
            v = (position[n - 1] - position[n - 2]) / (time[n - 1] - time[n - 2])
        else:
            dx1 = time[i] - time[i - 1]
            dx2 = time[i + 1] - time[i]
            a = -dx2 / (dx1 * (dx1 + dx2))
            b = (dx2 - dx1) / (dx1 * dx2)
            c = dx1 / (dx2 * (dx1 + dx2))
            v = a * position[i - 1] + b * position[i] + c * position[i + 1]
        p_out = load[i] * v
        block_through += abs(p_out)
        block_loss += torque[i] * speed[i] - p_out
        if i % 128 == 127 or i == n - 1:
            through += block_through
            loss += block_loss
            block_through = block_loss = 0.0
    return through, loss


@njit(cache=True)
def line_floors(amp, a, b, c, d, lines, floors):
    """lines[r, t] = max amp[r, a:b], floors[r, t] = median of amp[r, c:d] without
    amp[r, a:b] (np.median's value: the middle one, or the mean of the two middle ones), for
    every row r and target t with both ranges non-empty (the others are left as they are)."""
    buffer = np.empty(amp.shape[1])
    for r in range(a.shape[0]):
        for t in range(a.shape[1]):
            lo, hi, start, end = a[r, t], b[r, t], c[r, t], d[r, t]
            count = 0
            for i in range(start, min(lo, end)):
                buffer[count] = amp[r, i]
                count += 1
            for i in range(max(hi, start), end):
                buffer[count] = amp[r, i]
                count += 1
            if hi <= lo or count == 0:
                continue
            lines[r, t] = amp[r, lo:hi].max()
            around = np.sort(buffer[:count])
            upper = around[count // 2]
            lower = around[(count - 1) // 2]
            floors[r, t] = upper if count % 2 == 1 else (lower + upper) / 2
