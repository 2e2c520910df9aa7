/* SPDX-License-Identifier: Apache-2.0 */
/* Minimal register definitions for the STM32G474's own peripherals the
 * bristle port uses, written from the reference manual (RM0440) register
 * maps: RCC, PWR (CR5, the boost mode), FLASH (ACR) and the base addresses.
 * The blocks every STM32 port shares (TIMx up to BDTR, GPIO, IWDG, SysTick:
 * the same layout as on the H7; past BDTR the G4's TIM1 differs, with
 * CCR5/CCR6 at 0x48/0x4C and TISEL at 0x5C, registers no port uses) are in
 * hal/stm32 (bristle/br_stm32_regs.h).
 *
 * Each block is a struct of volatile 32-bit registers so that the port can be
 * pointed at the real peripheral address or, in host tests, at a plain struct
 * in RAM (a fake register block). Offsets are checked at compile time in
 * br_stm32g4.c. */
#ifndef BR_STM32G4_REGS_H
#define BR_STM32G4_REGS_H

#include <stdint.h>

#include "bristle/br_stm32_regs.h"

/* ---- Base addresses (RM0440 memory map; ARMv7-M for SysTick) ------------ */
#define BR_STM32G4_TIM2_BASE     0x40000000u  /* APB1, 32-bit GP timer */
#define BR_STM32G4_IWDG_BASE     0x40003000u  /* APB1, independent watchdog */
#define BR_STM32G4_PWR_BASE      0x40007000u  /* APB1 */
#define BR_STM32G4_TIM1_BASE     0x40012C00u  /* APB2, advanced timer */
#define BR_STM32G4_RCC_BASE      0x40021000u  /* AHB1 */
#define BR_STM32G4_FLASH_BASE    0x40022000u  /* AHB1, flash interface registers */
#define BR_STM32G4_GPIOA_BASE    0x48000000u  /* AHB2 */
#define BR_STM32G4_GPIOB_BASE    0x48000400u
#define BR_STM32G4_SYSTICK_BASE  BR_STM32_SYSTICK_BASE  /* Cortex-M4 system timer */
#define BR_STM32G4_USART2_BASE   0x40004400u  /* APB1 */
#define BR_STM32G4_DMA1_BASE     0x40020000u  /* AHB1 */
#define BR_STM32G4_DMAMUX1_BASE  0x40020800u  /* AHB1: request routing of DMA1 and DMA2 */

/* ---- RCC ------------------------------------------------------------------ */
typedef struct {
    volatile uint32_t CR;         /* 0x00 HSION, HSIRDY, PLLON, PLLRDY */
    volatile uint32_t ICSCR;      /* 0x04 */
    volatile uint32_t CFGR;       /* 0x08 SW, SWS, HPRE, PPRE1, PPRE2 */
    volatile uint32_t PLLCFGR;    /* 0x0C PLLSRC, PLLM, PLLN, PLLREN, PLLR */
    volatile uint32_t RESERVED0[2]; /* 0x10, 0x14 */
    volatile uint32_t CIER;       /* 0x18 */
    volatile uint32_t CIFR;       /* 0x1C */
    volatile uint32_t CICR;       /* 0x20 */
    volatile uint32_t RESERVED1;  /* 0x24 */
    volatile uint32_t AHB1RSTR;   /* 0x28 */
    volatile uint32_t AHB2RSTR;   /* 0x2C */
    volatile uint32_t AHB3RSTR;   /* 0x30 */
    volatile uint32_t RESERVED2;  /* 0x34 */
    volatile uint32_t APB1RSTR1;  /* 0x38 */
    volatile uint32_t APB1RSTR2;  /* 0x3C */
    volatile uint32_t APB2RSTR;   /* 0x40 */
    volatile uint32_t RESERVED3;  /* 0x44 */
    volatile uint32_t AHB1ENR;    /* 0x48 */
    volatile uint32_t AHB2ENR;    /* 0x4C GPIOAEN, GPIOBEN */
    volatile uint32_t AHB3ENR;    /* 0x50 */
    volatile uint32_t RESERVED4;  /* 0x54 */
    volatile uint32_t APB1ENR1;   /* 0x58 TIM2EN, PWREN */
    volatile uint32_t APB1ENR2;   /* 0x5C */
    volatile uint32_t APB2ENR;    /* 0x60 TIM1EN */
    volatile uint32_t RESERVED5[12]; /* 0x64..0x90: sleep-mode enables, CCIPR, BDCR */
    volatile uint32_t CSR;        /* 0x94 reset flags: IWDGRSTF, RMVF */
} br_stm32g4_rcc_t;

#define BR_G4_RCC_CR_HSION          (1u << 8)
#define BR_G4_RCC_CR_HSIRDY         (1u << 10)
#define BR_G4_RCC_CR_PLLON          (1u << 24)
#define BR_G4_RCC_CR_PLLRDY         (1u << 25)
#define BR_G4_RCC_CFGR_SW_Msk       (3u << 0)
#define BR_G4_RCC_CFGR_SW_PLL       (3u << 0)
#define BR_G4_RCC_CFGR_SWS_Msk      (3u << 2)
#define BR_G4_RCC_CFGR_SWS_PLL      (3u << 2)
#define BR_G4_RCC_CFGR_HPRE_Msk     (0xFu << 4)
#define BR_G4_RCC_CFGR_HPRE_DIV2    (8u << 4)  /* 1000: HCLK = SYSCLK / 2 */
#define BR_G4_RCC_CFGR_PPRE_Msk     (0x3Fu << 8) /* PPRE1[10:8], PPRE2[13:11]; 0xx: /1 */
#define BR_G4_RCC_PLLCFGR_PLLSRC_Msk (3u << 0)
#define BR_G4_RCC_PLLCFGR_PLLSRC_HSI (2u << 0)
#define BR_G4_RCC_PLLCFGR_PLLM_Pos  4u         /* M - 1, 4 bits */
#define BR_G4_RCC_PLLCFGR_PLLN_Pos  8u         /* N, 7 bits */
#define BR_G4_RCC_PLLCFGR_PLLREN    (1u << 24)
#define BR_G4_RCC_PLLCFGR_PLLR_Pos  25u        /* PLLR[26:25], 00: /2 */
#define BR_G4_RCC_AHB2ENR_GPIOAEN   (1u << 0)
#define BR_G4_RCC_AHB2ENR_GPIOBEN   (1u << 1)
#define BR_G4_RCC_APB1ENR1_TIM2EN   (1u << 0)
#define BR_G4_RCC_APB1ENR1_USART2EN (1u << 17)
#define BR_G4_RCC_AHB1ENR_DMA1EN    (1u << 0)
#define BR_G4_RCC_AHB1ENR_DMAMUX1EN (1u << 2)
#define BR_G4_RCC_APB1ENR1_PWREN    (1u << 28)
#define BR_G4_RCC_APB2ENR_TIM1EN    (1u << 11)
#define BR_G4_RCC_CSR_RMVF          (1u << 23)
#define BR_G4_RCC_CSR_IWDGRSTF      (1u << 29)

/* ---- PWR (only CR5: range 1 boost mode) ----------------------------------- */
typedef struct {
    volatile uint32_t CR1;           /* 0x00 VOS */
    volatile uint32_t RESERVED0[31]; /* 0x04..0x7C */
    volatile uint32_t CR5;           /* 0x80 R1MODE: 0 = boost (up to 170 MHz) */
} br_stm32g4_pwr_t;

#define BR_G4_PWR_CR5_R1MODE (1u << 8)

/* ---- FLASH (only ACR) ------------------------------------------------------ */
typedef struct {
    volatile uint32_t ACR; /* 0x00 LATENCY[3:0], PRFTEN, ICEN, DCEN */
} br_stm32g4_flash_t;

#define BR_G4_FLASH_ACR_LATENCY_Msk 0xFu
#define BR_G4_FLASH_ACR_PRFTEN      (1u << 8)
#define BR_G4_FLASH_ACR_ICEN        (1u << 9)
#define BR_G4_FLASH_ACR_DCEN        (1u << 10)

/* ---- DMA1 / DMA2 (RM0440 "DMA registers") and DMAMUX ------------------- */
/* One channel: the four registers every STM32 port's DMA shares
 * (br_stm32_dma_ch_t: CCRx, CNDTRx, CPARx, CMARx), then a reserved word. */
typedef struct {
    br_stm32_dma_ch_t ch;       /* 0x08 + 0x14 (x - 1), x = 1..8 */
    volatile uint32_t RESERVED; /* 0x18 + 0x14 (x - 1) */
} br_stm32g4_dma_channel_t;

typedef struct {
    volatile uint32_t ISR;  /* 0x00 */
    volatile uint32_t IFCR; /* 0x04 CGIFx, CTCIFx, CHTIFx, CTEIFx at 4 (x - 1) */
    br_stm32g4_dma_channel_t C[8]; /* C[0] is channel 1 */
} br_stm32g4_dma_t;

/* CCRx */
#define BR_G4_DMA_CCR_DIR_M2P   (1u << 4) /* 1: read from memory */
#define BR_G4_DMA_CCR_CIRC      (1u << 5)
#define BR_G4_DMA_CCR_MINC      (1u << 7) /* PSIZE, MSIZE 00: bytes */
#define BR_G4_DMA_IFCR_CHANNEL  0xFu
#define BR_G4_DMA_CHANNELS      8u

/* DMAMUX: channel k routes a request to DMA1 channel k + 1 (k = 0..7) and
 * DMA2 channel k - 7 (8..15); DMAREQ_ID in bits 6:0 of CkCR. */
typedef struct {
    volatile uint32_t CCR[16]; /* 0x00 + 4 k */
} br_stm32g4_dmamux_t;

#define BR_G4_DMAMUX_REQ_MAX    0x7Fu
/* RM0440 table "DMAMUX: assignment of multiplexer inputs to resources" */
#define BR_G4_DMAREQ_USART2_RX  26u
#define BR_G4_DMAREQ_USART2_TX  27u

#endif
