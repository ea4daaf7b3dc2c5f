// specfx_quant: quantization of an exact value into a fixed-point format, bit for bit as
// src/fixed/quantize.rs (`quantize`): round to the output LSB with the rounding mode RND, then
// handle overflow with the mode OVF, as ac_fixed does on assignment.
//
// The input x is exact: the raw code of IN_W bits stands for x * 2^-IN_F (two's complement when
// IN_S = 1). The output y is a raw code of OUT_W bits standing for y * 2^-OUT_F (two's
// complement when OUT_S = 1). Fraction bits may be negative; SH = IN_F - OUT_F may be
// positive (SH bits dropped with rounding), zero or negative (an exact left shift).
//
// Rounding codes (RND): 0 TRN, 1 TRN_ZERO, 2 RND, 3 RND_ZERO, 4 RND_INF, 5 RND_MIN_INF,
// 6 RND_CONV, 7 RND_CONV_ODD.
// Overflow codes (OVF): 0 WRAP (keep the low OUT_W bits), 1 SAT (clamp to [min, max]),
// 2 SAT_ZERO (out of range gives 0), 3 SAT_SYM (signed formats clamp to [-max, max]; as in
// ac_fixed, every value <= min, min itself included, gives min | 1; unsigned formats as SAT).
//
// Purely combinational; every intermediate is exact (Verilog vectors of any width).
`timescale 1ns / 1ps
`default_nettype none

module specfx_quant #(
    parameter integer IN_W  = 8,
    parameter integer IN_F  = 0,
    parameter integer IN_S  = 1,
    parameter integer OUT_W = 8,
    parameter integer OUT_F = 0,
    parameter integer OUT_S = 1,
    parameter integer RND   = 0,
    parameter integer OVF   = 0
) (
    input  wire [IN_W-1:0]  x,
    output wire [OUT_W-1:0] y
);
    localparam integer SH = IN_F - OUT_F;
    // x as a signed value: one extra bit holds unsigned inputs.
    localparam integer XW = IN_W + 1;

    wire [XW-1:0] xs;
    specfx_extend #(.IN_W(IN_W), .IN_S(IN_S), .OUT_W(XW)) u_xs (.x(x), .y(xs));

    // ---- Rounding: `rounded` is the value in output LSBs, a signed RW-bit code. ----
    // RW: right shift: the floor keeps FW = EW - SH bits, one more bit takes the carry of
    // rounding up; left shift: XW + (-SH) bits.
    localparam integer EW = (XW > SH) ? XW : SH + 1;
    localparam integer FW = EW - SH;
    localparam integer RW = (SH > 0) ? FW + 1 : XW - SH;

    wire [RW-1:0] rounded;

    generate
        if (SH > 0) begin : g_round
            // floor(x / 2^SH) is the top of the sign-extended value; the SH dropped bits are
            // compared with half an output LSB.
            wire [EW-1:0] xe;
            specfx_extend #(.IN_W(XW), .IN_S(1), .OUT_W(EW)) u_xe (.x(xs), .y(xe));
            wire negative = xs[XW-1];
            wire [FW-1:0] floor_q = xe[EW-1:SH];
            wire [SH-1:0] dropped = xe[SH-1:0];
            wire dropped_msb = dropped[SH-1];
            wire dropped_low;  // any dropped bit below the half position is set
            if (SH > 1) begin : g_low
                assign dropped_low = |dropped[SH-2:0];
            end else begin : g_nolow
                assign dropped_low = 1'b0;
            end
            wire is_zero  = !dropped_msb && !dropped_low;
            wire is_half  = dropped_msb && !dropped_low;
            wire is_above = dropped_msb && dropped_low;
            wire floor_odd = floor_q[0];
            // What to do on an exact tie (remainder = half an LSB), per mode.
            wire tie_up = (RND == 2) ? 1'b1 :             // RND: towards +inf
                          (RND == 3) ? negative :         // RND_ZERO: towards 0
                          (RND == 4) ? !negative :        // RND_INF: away from 0
                          (RND == 5) ? 1'b0 :             // RND_MIN_INF: towards -inf
                          (RND == 6) ? floor_odd :        // RND_CONV: to even
                          (RND == 7) ? !floor_odd :       // RND_CONV_ODD: to odd
                                       1'b0;
            wire round_up = (RND == 0) ? 1'b0 :                     // TRN: floor
                            (RND == 1) ? (negative && !is_zero) :   // TRN_ZERO: towards 0
                                         (is_above || (is_half && tie_up));
            wire [RW-1:0] up = {{(RW - 1){1'b0}}, round_up};
            assign rounded = {floor_q[FW-1], floor_q} + up;
        end else if (SH == 0) begin : g_same
            assign rounded = xs;
        end else begin : g_left
            assign rounded = {xs, {(-SH){1'b0}}};
        end
    endgenerate

    // ---- Overflow: compare with the output range on CW signed bits. ----
    localparam integer CW = (RW > OUT_W + 1) ? RW : OUT_W + 1;
    localparam integer MAX_BITS = OUT_W - OUT_S;  // max = 2^MAX_BITS - 1

    wire [CW-1:0] value;
    specfx_extend #(.IN_W(RW), .IN_S(1), .OUT_W(CW)) u_value (.x(rounded), .y(value));
    wire [OUT_W-1:0] kept = value[OUT_W-1:0];  // the low OUT_W bits: the WRAP result

    generate
        if (OVF == 0) begin : g_wrap
            assign y = kept;
            wire _unused_ok = &{1'b0, value[CW-1:OUT_W]};
        end else begin : g_saturate
            wire [CW-1:0] one = {{(CW - 1){1'b0}}, 1'b1};
            wire [CW-1:0] max_code = (one << MAX_BITS) - one;
            wire [CW-1:0] min_code = (OUT_S != 0) ? ~max_code : {CW{1'b0}};
            wire above_max = $signed(value) > $signed(max_code);
            wire below_min = $signed(value) < $signed(min_code);
            if (OVF == 2) begin : g_sat_zero
                assign y = (above_max || below_min) ? {OUT_W{1'b0}} : kept;
                wire _unused_ok = &{1'b0, max_code[OUT_W-1:0], min_code[OUT_W-1:0]};
            end else if (OVF == 3 && OUT_S != 0) begin : g_sat_sym
                wire [OUT_W-1:0] max_out = max_code[OUT_W-1:0];
                wire [OUT_W-1:0] min_out = min_code[OUT_W-1:0];
                // ac_fixed: every value <= min, min included, gives min | 1 (= -max).
                wire low = below_min || (value == min_code);
                wire [OUT_W-1:0] sym_min_out = min_out | {{(OUT_W - 1){1'b0}}, 1'b1};
                assign y = low ? sym_min_out : above_max ? max_out : kept;
            end else begin : g_sat  // SAT, and SAT_SYM of an unsigned format
                wire [OUT_W-1:0] max_out = max_code[OUT_W-1:0];
                wire [OUT_W-1:0] min_out = min_code[OUT_W-1:0];
                assign y = below_min ? min_out : above_max ? max_out : kept;
            end
            wire _unused_ok = &{1'b0, max_code[CW-1:OUT_W], min_code[CW-1:OUT_W]};
        end
    endgenerate
endmodule

`default_nettype wire
