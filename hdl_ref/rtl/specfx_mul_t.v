// specfx_mul_t: t = Q_t(d * slope) (Rust: the t stage of src/pipeline/datapath.rs `eval`).
// d is signed (D_W bits, D_F fraction bits); the slope has SLOPE_W bits, SLOPE_F fraction bits
// (plain variant: n with k fraction bits, i.e. n/2^k; minimax: A(n)). The exact product has
// D_F + SLOPE_F fraction bits and is quantized to T with T_RND and T_OVF. Combinational.
// SLOPE_POW2 = 1 (plain variant, every n a power of two, so the slope is one-hot): the product
// is d shifted left by the position of the slope's one bit, a multiplexer instead of a
// multiplier, equal to d * slope for every one-hot slope.
`timescale 1ns / 1ps
`default_nettype none

module specfx_mul_t #(
    parameter integer D_W     = 16,
    parameter integer D_F     = 15,
    parameter integer SLOPE_W = 11,
    parameter integer SLOPE_F = 4,
    parameter integer SLOPE_S = 0,
    parameter integer T_W     = 18,
    parameter integer T_F     = 16,
    parameter integer T_S     = 1,
    parameter integer T_RND   = 2,
    parameter integer T_OVF   = 1,
    parameter integer SLOPE_POW2 = 0
) (
    input  wire [D_W-1:0]     d,
    input  wire [SLOPE_W-1:0] slope,
    output wire [T_W-1:0]     t
);
    localparam integer P_W = D_W + SLOPE_W;  // d is signed
    wire [P_W-1:0] product;
    generate
        if (SLOPE_POW2 != 0) begin : g_shift
            wire [P_W-1:0] d_ext = {{SLOPE_W{d[D_W-1]}}, d};
            reg  [P_W-1:0] shifted;
            integer i;
            always @* begin
                shifted = {P_W{1'b0}};
                for (i = 0; i < SLOPE_W; i = i + 1) begin
                    if (slope[i]) shifted = shifted | (d_ext << i);
                end
            end
            assign product = shifted;
        end else begin : g_mul
            specfx_mul #(.A_W(D_W), .A_S(1), .B_W(SLOPE_W), .B_S(SLOPE_S), .P_W(P_W)) u_mul (
                .a(d), .b(slope), .p(product)
            );
        end
    endgenerate
    specfx_quant #(
        .IN_W(P_W), .IN_F(D_F + SLOPE_F), .IN_S(1),
        .OUT_W(T_W), .OUT_F(T_F), .OUT_S(T_S), .RND(T_RND), .OVF(T_OVF)
    ) u_q (
        .x(product), .y(t)
    );
endmodule

`default_nettype wire
