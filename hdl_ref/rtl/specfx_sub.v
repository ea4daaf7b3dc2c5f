// specfx_sub: d = c - 1 (Rust: the d stage of src/pipeline/datapath.rs `eval`).
// The input c (C_W bits, C_F fraction bits, two's complement when C_S = 1) is first clamped to
// 1.0 = 1 << C_F (inputs above 1.0 become 1.0), then d = (c_clamped - one) << (D_F - C_F),
// exact in the signed format D (D_W bits, D_F fraction bits; validated by the Rust model:
// C_F >= 0, D_F >= C_F, and D holds c - 1 for every input). Combinational.
`timescale 1ns / 1ps
`default_nettype none

module specfx_sub #(
    parameter integer C_W = 16,
    parameter integer C_F = 15,
    parameter integer C_S = 0,
    parameter integer D_W = 16,
    parameter integer D_F = 15
) (
    input  wire [C_W-1:0] c,
    output wire [C_W-1:0] c_clamped,  // min(c, 1.0), for the paper cutoff
    output wire [D_W-1:0] d
);
    localparam integer XW = C_W + 2;          // c and c - 1 as signed values
    localparam integer D_SHIFT = D_F - C_F;
    localparam integer SW = XW + D_SHIFT;     // (c - 1) << D_SHIFT
    localparam integer OW = (SW > D_W) ? SW : D_W;

    wire [XW-1:0] c_x;
    specfx_extend #(.IN_W(C_W), .IN_S(C_S), .OUT_W(XW)) u_c (.x(c), .y(c_x));
    wire [XW-1:0] one = {{(XW - 1){1'b0}}, 1'b1} << C_F;
    wire above_one = $signed(c_x) > $signed(one);
    wire [XW-1:0] c_cl_x = above_one ? one : c_x;
    assign c_clamped = c_cl_x[C_W-1:0];

    wire [XW-1:0] diff = c_cl_x - one;
    wire [SW-1:0] diff_x;
    specfx_extend #(.IN_W(XW), .IN_S(1), .OUT_W(SW)) u_diff (.x(diff), .y(diff_x));
    wire [OW-1:0] shifted_x;
    specfx_extend #(.IN_W(SW), .IN_S(1), .OUT_W(OW)) u_shifted (.x(diff_x << D_SHIFT), .y(shifted_x));
    assign d = shifted_x[D_W-1:0];
    generate
        if (OW > D_W) begin : g_unused
            // c - 1 fits D exactly (validated): the dropped top bits are copies of the sign.
            wire _unused_ok = &{1'b0, shifted_x[OW-1:D_W], c_cl_x[XW-1:C_W]};
        end else begin : g_unused_c
            wire _unused_ok = &{1'b0, c_cl_x[XW-1:C_W]};
        end
    endgenerate
endmodule

`default_nettype wire
