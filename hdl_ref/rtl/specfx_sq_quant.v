// specfx_sq_quant: the quantizer of squaring stage i, with its bypass multiplexer (Rust:
// `Datapath::op_stage` in src/pipeline/datapath.rs; docs/arithmetic.md, step 5). It takes the
// exact square `product` of the stage's input x (P_W bits, two's complement, 2 X_F fraction
// bits) and quantizes it to Y with Y_RND and Y_OVF. With BYPASS = 1, `pass` high selects x
// itself instead (an n whose depth j(n) is below this stage): x and the square are aligned on
// max(2 X_F, X_F) fraction bits ahead of the same quantizer, so a bypassed stage requantizes
// its input with its own format and modes, exactly as the model. BYPASS = 0 is the plain
// quantizer (x and pass unused). Combinational.
`timescale 1ns / 1ps
`default_nettype none

module specfx_sq_quant #(
    parameter integer P_W    = 35,
    parameter integer X_W    = 17,
    parameter integer X_F    = 16,
    parameter integer X_S    = 0,
    parameter integer Y_W    = 17,
    parameter integer Y_F    = 16,
    parameter integer Y_S    = 0,
    parameter integer Y_RND  = 2,
    parameter integer Y_OVF  = 1,
    parameter integer BYPASS = 0
) (
    input  wire [P_W-1:0] product,
    input  wire [X_W-1:0] x,
    input  wire           pass,
    output wire [Y_W-1:0] y
);
    generate
        if (BYPASS == 0) begin : g_square
            specfx_quant #(
                .IN_W(P_W), .IN_F(2 * X_F), .IN_S(1),
                .OUT_W(Y_W), .OUT_F(Y_F), .OUT_S(Y_S), .RND(Y_RND), .OVF(Y_OVF)
            ) u_q (
                .x(product), .y(y)
            );
            wire _unused_ok = &{1'b0, x, pass};
        end else begin : g_bypass
            // The common fraction bits and each side's left shift onto them.
            localparam integer AL_F = (X_F > 0) ? 2 * X_F : X_F;
            localparam integer P_SH = AL_F - 2 * X_F;
            localparam integer X_SH = AL_F - X_F;
            localparam integer A_W0 = P_W + P_SH;
            localparam integer A_W1 = X_W + 1 + X_SH;
            localparam integer A_W = (A_W0 > A_W1) ? A_W0 : A_W1;
            wire [A_W-1:0] p_e;
            wire [A_W-1:0] x_e;
            specfx_extend #(.IN_W(P_W), .IN_S(1), .OUT_W(A_W)) u_p_e (.x(product), .y(p_e));
            specfx_extend #(.IN_W(X_W), .IN_S(X_S), .OUT_W(A_W)) u_x_e (.x(x), .y(x_e));
            wire [A_W-1:0] aligned = pass ? (x_e << X_SH) : (p_e << P_SH);
            specfx_quant #(
                .IN_W(A_W), .IN_F(AL_F), .IN_S(1),
                .OUT_W(Y_W), .OUT_F(Y_F), .OUT_S(Y_S), .RND(Y_RND), .OVF(Y_OVF)
            ) u_q (
                .x(aligned), .y(y)
            );
        end
    endgenerate
endmodule

`default_nettype wire
