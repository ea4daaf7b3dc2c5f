// specfx_add_b: b = Q_b(cutoff(t + offset)) (Rust: the b stage of src/pipeline/datapath.rs
// `eval`). The sum is exact, aligned on max(T_F, OFFSET_F) fraction bits. The cutoff forces
// it to 0: CUTOFF 0 (clamp) when the sum is negative; 1 (paper) when the clamped input is below
// the per-n threshold code (c_clamped < threshold, both in c's format); 2 (none) never.
// The result is quantized to B with B_RND and B_OVF. Combinational.
`timescale 1ns / 1ps
`default_nettype none

module specfx_add_b #(
    parameter integer T_W      = 18,
    parameter integer T_F      = 16,
    parameter integer T_S      = 1,
    parameter integer OFFSET_W = 1,
    parameter integer OFFSET_F = 0,
    parameter integer OFFSET_S = 0,
    parameter integer C_W      = 16,
    parameter integer C_S      = 0,
    parameter integer CUTOFF   = 0,
    parameter integer B_W      = 17,
    parameter integer B_F      = 16,
    parameter integer B_S      = 0,
    parameter integer B_RND    = 2,
    parameter integer B_OVF    = 1
) (
    input  wire [T_W-1:0]      t,
    input  wire [OFFSET_W-1:0] offset,
    input  wire [C_W-1:0]      c_clamped,  // used by the paper cutoff only
    input  wire [C_W-1:0]      threshold,  // used by the paper cutoff only
    output wire [B_W-1:0]      b
);
    localparam integer SUM_F = (T_F > OFFSET_F) ? T_F : OFFSET_F;
    localparam integer T_SHIFT = SUM_F - T_F;
    localparam integer O_SHIFT = SUM_F - OFFSET_F;
    localparam integer T_AW = T_W + T_SHIFT;       // aligned widths
    localparam integer O_AW = OFFSET_W + O_SHIFT;
    localparam integer SUM_W = ((T_AW > O_AW) ? T_AW : O_AW) + 2;  // signed, exact

    wire [SUM_W-1:0] t_x;
    wire [SUM_W-1:0] offset_x;
    specfx_extend #(.IN_W(T_W), .IN_S(T_S), .OUT_W(SUM_W)) u_t (.x(t), .y(t_x));
    specfx_extend #(.IN_W(OFFSET_W), .IN_S(OFFSET_S), .OUT_W(SUM_W)) u_o (.x(offset), .y(offset_x));
    wire [SUM_W-1:0] sum = (t_x << T_SHIFT) + (offset_x << O_SHIFT);
    wire cut;  // the cutoff forces the sum to 0

    generate
        if (CUTOFF == 0) begin : g_clamp
            assign cut = sum[SUM_W-1];
            wire _unused_ok = &{1'b0, c_clamped, threshold};
        end else if (CUTOFF == 1) begin : g_paper
            if (C_S != 0) begin : g_signed
                assign cut = $signed(c_clamped) < $signed(threshold);
            end else begin : g_unsigned
                assign cut = c_clamped < threshold;
            end
        end else begin : g_none
            assign cut = 1'b0;
            wire _unused_ok = &{1'b0, c_clamped, threshold};
        end
    endgenerate

    wire [SUM_W-1:0] base = cut ? {SUM_W{1'b0}} : sum;
    specfx_quant #(
        .IN_W(SUM_W), .IN_F(SUM_F), .IN_S(1),
        .OUT_W(B_W), .OUT_F(B_F), .OUT_S(B_S), .RND(B_RND), .OVF(B_OVF)
    ) u_q (
        .x(base), .y(b)
    );
endmodule

`default_nettype wire
